"""tf-plus-track: a jump must be earned, an impossible odometry increment is doubted."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import tfloc
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate
from tfloc.harness.track import track
from tfloc.io.scenario import read_scans, read_scenario
from tfloc.tfplus.tracker import TfPlusTracker

ROOT = Path(__file__).resolve().parents[2]


class Stub:
    """A matcher answering ``answers[guess's x rounded]`` (pose, cost), cost reported as tf-plus does."""

    def __init__(self, answers):
        self.answers, self.asked = answers, []

    def localize(self, problem):
        self.asked.append(problem.initial)
        pose, cost = self.answers(problem.initial)
        return Estimate(pose, True, info={"status": "ok", "cost": cost})


def _tracker(far, near, **cfg) -> TfPlusTracker:
    t = TfPlusTracker(**cfg)
    t.matcher, t.near = Stub(far), Stub(near)
    room = tfloc.load_map(ROOT / "data" / "maps" / "test-room.geojson")
    t.start(room, tfloc.LaserSpec.lms200(), Pose(2.0, 2.0, 0.0))
    return t


RANGES = np.full(181, 3.0)


@pytest.mark.parametrize(("far_cost", "near_cost", "kept"), [(0.01**2, 0.012**2, "near"),
                                                            (0.01**2, 0.02**2, "far")])
def test_a_jump_is_kept_only_if_it_explains_the_scan_much_better(far_cost, near_cost, kept):
    t = _tracker(lambda g: (Pose(g.x + 2.0, g.y, g.theta), far_cost),     # 2 m away
                 lambda g: (Pose(g.x + 0.02, g.y, g.theta), near_cost))
    est = t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    assert est.info["jump"] and est.info["kept"] == kept
    assert est.pose.x == pytest.approx(2.1 + (2.0 if kept == "far" else 0.02))
    assert t.pose == est.pose


def test_a_small_correction_is_no_jump():
    t = _tracker(lambda g: (Pose(g.x + 0.05, g.y, g.theta), 1e-4), lambda g: (g, 0.0))
    est = t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    assert not est.info["jump"] and est.info["kept"] == "far" and not t.near.asked


def test_an_impossible_increment_is_also_tried_as_no_motion():
    """An encoder that froze and caught up: 85° in one scan. From the last estimate (no motion)
    tf-plus finds a better pose than from the prediction; a plausible increment is not doubted."""
    good = Pose(2.0, 2.0, 0.1)
    t = _tracker(lambda g: (good, 1e-6) if abs(g.theta) < 0.2 else (g, 1e-2), lambda g: (g, 1e-2))
    est = t.step(RANGES, Pose(0.4, 0.0, math.radians(85.0)), 0.0)
    assert est.info["doubted_odometry"] and est.info["kept"] == "still" and est.pose == good
    t2 = _tracker(lambda g: (g, 1e-4), lambda g: (g, 1e-4))
    assert not t2.step(RANGES, Pose(0.1, 0.0, 0.1), 0.0).info["doubted_odometry"]


def test_tracks_a_simulated_sequence_like_tf_plus():
    sc = read_scenario(ROOT / "data" / "scenarios" / "seq-quick")
    scans = read_scans(sc)[:40]
    a = track(sc, scans, tfloc.get_matcher("tf-plus-track"))
    b = track(sc, scans, tfloc.get_matcher("tf-plus"))
    assert [r["est_x"] for r in a] == [r["est_x"] for r in b]        # no jump on an easy route
    assert all(r["status"] == "ok" for r in a)


def test_its_residual_is_tf_plus_score():
    sc = read_scenario(ROOT / "data" / "scenarios" / "seq-quick")
    s = read_scans(sc)[0]
    t = tfloc.get_matcher("tf-plus-track")
    from tfloc.harness.workspace import problem_of

    problem = problem_of(sc, s)
    est = t.matcher.localize(problem)
    assert t._residual(t.matcher, problem, est) == pytest.approx(t.matcher.score(problem, est.pose), rel=1e-9)
