"""tf-plus-track: a jump must be earned, an impossible odometry increment is doubted, a trusted
prediction is searched in its window and widened when the answer does not fit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _paths import ROOT

import tfloc
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem
from tfloc.harness.track import odom_deltas, track
from tfloc.harness.workspace import map_of
from tfloc.io.scenario import load_dataset, map_for, read_scans, read_scenario
from tfloc.tfplus import pipeline
from tfloc.tfplus.matcher import TurningFunctionPlusMatcher
from tfloc.tfplus.tracker import TfPlusTracker, window_config


class Stub:
    """A matcher answering ``answers(guess)`` = (pose, cost), cost reported as tf-plus does; its
    ``score`` at a pose is ``fit`` (metres; default: the root of the cost it would answer there)."""

    def __init__(self, answers, fit=None):
        self.answers, self.asked, self.fit, self.problems = answers, [], fit, []

    def localize(self, problem):
        self.asked.append(problem.initial)
        self.problems.append(problem)
        pose, cost = self.answers(problem.initial)
        return Estimate(pose, True, info={"status": "ok", "cost": cost})

    def score(self, problem, pose):
        return self.fit if self.fit is not None else math.sqrt(self.answers(pose)[1])


def _tracker(far, near, window=None, laser=None, **cfg) -> TfPlusTracker:
    t = TfPlusTracker(**cfg)
    t.matcher, t.near, t.window = Stub(far), Stub(near), Stub(window or far)
    room = tfloc.load_map(ROOT / "data" / "maps" / "test-room.geojson")
    t.start(room, laser or tfloc.LaserSpec.lms200(), Pose(2.0, 2.0, 0.0))
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


def test_a_trusted_prediction_is_searched_in_its_window_and_widened_when_it_does_not_fit():
    near_answer = lambda g: (Pose(g.x + 0.02, g.y, g.theta), 0.01**2)    # noqa: E731
    t = _tracker(near_answer, near_answer, lambda g: (Pose(g.x + 0.01, g.y, g.theta), 0.03**2))
    t.window.fit = 0.01                                        # the protocol's window's answers fit
    first = t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)          # not trusted yet: the protocol's window
    assert first.info["kept"] == "far" and not t.window.asked and t.trusted
    est = t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)            # trusted, and the window's answer fits
    assert est.info["kept"] == "window" and not est.info["widened"] and len(t.matcher.asked) == 1
    assert est.pose.x == pytest.approx(2.23) and est.info["score"] == pytest.approx(0.03)
    t.window.answers = lambda g: (g, 0.05**2)                  # residual 5 cm > widen_score: no fit
    est = t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    assert est.info["widened"] and est.info["kept"] == "far" and len(t.matcher.asked) == 2
    assert t.matcher.problems[-1] is t.window.problems[-1]     # one problem (one check) per step
    t.window.answers = lambda g: (Pose(g.x + 0.6, g.y, g.theta), 0.01**2)  # fits, but a jump
    est = t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    assert est.info["widened"] and est.info["kept"] == "far" and len(t.matcher.asked) == 3
    asked = len(t.window.asked)
    assert t.step(RANGES, Pose(0.6, 0.0, 0.0), 0.0).info["doubted_odometry"]   # doubted: no window
    assert len(t.window.asked) == asked


def test_an_answer_that_does_not_fit_is_no_trusted_prediction():
    t = _tracker(lambda g: (g, 0.05**2), lambda g: (g, 0.05**2))
    t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    assert not t.trusted and not t.window.asked and len(t.matcher.asked) == 2
    t = _tracker(lambda g: (g, 0.01**2), lambda g: (g, 0.01**2), trusted_window=False)
    t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    assert not t.window.asked and len(t.matcher.asked) == 2


@pytest.mark.parametrize(("fit", "trusted"), [(0.02, True), (0.05, False)])
def test_the_fit_is_the_point_to_line_residual_not_the_selection_cost(fit, trusted):
    """The protocol's window's answer is judged by the window's objective (the point-to-line
    residual), whatever its selection cost with the see-through term: a selection residual of 8 cm
    with a point-to-line residual of 2 cm fits, one of 5 cm does not."""
    t = _tracker(lambda g: (g, 0.08**2), lambda g: (g, 0.08**2))
    t.window.fit = fit
    est = t.step(RANGES, Pose(0.1, 0.0, 0.0), 0.0)
    assert est.info["kept"] == "far" and t.trusted == trusted
    assert est.info["score"] == pytest.approx(fit)


@pytest.mark.parametrize(("resolution_deg", "spacing_deg", "stride"), [(0.5, 1.0, 2), (1.0, 1.0, 1),
                                                                       (0.5, 0.0, 1), (0.25, 1.0, 4)])
def test_the_window_reads_beams_a_degree_apart(resolution_deg, spacing_deg, stride):
    """A 0.5° scanner's window and fit read every other beam, a 1° scanner's every beam; the
    protocol's window reads them all."""
    laser = tfloc.LaserSpec.from_degrees(10.0, 180.0, resolution_deg)
    ranges = np.linspace(2.0, 3.0, laser.n_beams)
    t = _tracker(lambda g: (g, 0.01**2), lambda g: (g, 0.01**2), laser=laser,
                 window_spacing=math.radians(spacing_deg))
    t.step(ranges, Pose(0.1, 0.0, 0.0), 0.0)                   # the protocol's window, all beams
    t.step(ranges, Pose(0.1, 0.0, 0.0), 0.0)                   # the trusted window
    full, window = t.matcher.problems[-1], t.window.problems[-1]
    assert full.laser is laser and len(full.ranges) == laser.n_beams
    assert window.ranges.tobytes() == ranges[::stride].tobytes() and t.stride == stride
    assert window.laser.n_beams == len(window.ranges) and window.laser is t.window_laser


def _seq_quick(n: int):
    sc = read_scenario(ROOT / "data" / "scenarios" / "seq-quick")
    return sc, read_scans(sc)[:n]


def test_tracks_a_simulated_sequence_like_tf_plus():
    """Without the window, exactly ``tf-plus`` on an easy route (no jump); with it, the window's
    answers from the second scan on, the same poses to a few millimetres."""
    sc, scans = _seq_quick(40)
    b = track(sc, scans, tfloc.get_matcher("tf-plus"))
    a = track(sc, scans, tfloc.get_matcher("tf-plus-track", trusted_window=False))
    assert [r.est_x for r in a] == [r.est_x for r in b]
    w = track(sc, scans, tfloc.get_matcher("tf-plus-track"))
    assert [r.info["kept"] for r in w] == ["far"] + ["window"] * 39
    assert all(r.status.ok for r in a + w)
    for r, q in zip(w, b, strict=True):
        p, o = Pose(r.est_x, r.est_y, r.est_theta), Pose(q.est_x, q.est_y, q.est_theta)
        d, turn = p.error_to(o)
        assert d < 0.005 and turn < math.radians(0.2)


@pytest.mark.parametrize(("widen_score", "recovers"), [(0.04, True), (1.0, False)])
def test_a_kidnapped_prediction_widens_and_recovers(widen_score, recovers):
    """The robot is carried 1 m sideways while the tracker trusts its prediction: the window's
    answer does not fit, the protocol's window finds the robot (a jump it earns). Never widened
    (``widen_score`` above any residual), the tracker stays lost: the rule is what recovers."""
    sc, scans = _seq_quick(32)
    t = tfloc.get_matcher("tf-plus-track", widen_score=widen_score)
    the_map = map_for(sc, scans[0], {})
    t.warm(the_map, sc.laser, scans[0].ranges, scans[0].initial)
    t.start(the_map, sc.laser, scans[0].initial)
    deltas = odom_deltas(scans)
    for k in range(30):
        est = t.step(scans[k].ranges, deltas[k], scans[k].stamp)
    assert t.trusted and est.info["kept"] == "window"
    t.pose = scans[29].true.compose(Pose(0.0, -1.0, 0.0))     # kidnapped; the tracker still trusts
    est = t.step(scans[30].ranges, deltas[30], scans[30].stamp)
    d, turn = est.pose.error_to(scans[30].true)
    assert est.info["widened"] == recovers
    assert (d < 0.02 and turn < math.radians(1.0)) if recovers else d > 0.5


@pytest.mark.parametrize(("spacing_deg", "within", "median"), [(0.0, 0.03, 0.002), (1.0, 0.02, 0.01)])
def test_window_answers_equal_the_full_search_s(spacing_deg, within, median):
    """From a guess inside the window, where the full search's answer lies in the window too, the
    window's answer is that pose (to the refinement's convergence: the coarse searches start it
    from different lattice poses) or does not fit and is widened. MIT CSAIL's corrected scans:
    on every beam, a few millimetres apart; on every other beam (its 0.5° scanner read 1° apart,
    the default), within 1.3 cm (median 6 mm) and as near the corrected pose as the full search."""
    scenario, by_id = load_dataset(str(ROOT / "data" / "scenarios" / "real-csail-scan-to-map"))
    scans = list(by_id.values())[::12]
    t = TfPlusTracker(window_spacing=math.radians(spacing_deg))
    full, cfg = TurningFunctionPlusMatcher(), t.config
    rng = np.random.default_rng(3)
    apart, errors = [], []
    for k, scan in enumerate(scans):
        guess = scan.true.compose(Pose(*rng.uniform(-0.15, 0.15, 2), rng.uniform(-0.2, 0.2)))
        p = Problem(map_of(scenario, scan), scenario.laser, scan.ranges, guess)
        if k == 0:
            t.warm(p.map, p.laser, p.ranges, guess)
            full.prepare(p)
            assert t.stride == (2 if spacing_deg else 1)
            assert pipeline.plan_for(t._thinned(p), t.window.config) is not None   # one compiled call
        a, b = t._in_window(p)[0], full.localize(p)
        if b.pose.distance_to(guess) > cfg.window_m or not abs(b.pose.theta - guess.theta) < cfg.window_rad:
            continue
        if a is None:
            continue                                                # widened: the full search answers
        d, turn = a.pose.error_to(b.pose)
        assert d < within and turn < math.radians(1.0), (scan.scan_id, d, turn)
        apart.append(d)
        errors.append((a.pose.distance_to(scan.true), b.pose.distance_to(scan.true)))
    assert len(apart) >= 25 and float(np.median(apart)) < median
    window_error, full_error = np.median(errors, axis=0)
    assert window_error < full_error + 0.002


def test_the_window_is_tf_plus_in_a_smaller_window():
    cfg = TfPlusTracker(window_m=0.25, window_rad=0.1).config
    w = window_config(cfg)
    assert (w.search_radius, w.heading_span, w.tf_seed, w.candidates) == (0.25, 0.1, False, 1)
    assert not w.beam_check and cfg.local.beam_check      # one candidate: no see-through term
    assert w.refinement.gate_end == cfg.local.refinement.gate_end and w.refinement.iterations == 4
    assert window_config(TfPlusTracker(window_m=9.0, window_rad=3.0).config).search_radius == cfg.local.search_radius


def test_its_residual_is_tf_plus_score():
    sc = read_scenario(ROOT / "data" / "scenarios" / "seq-quick")
    s = read_scans(sc)[0]
    t = tfloc.get_matcher("tf-plus-track")
    from tfloc.harness.workspace import problem_of

    problem = problem_of(sc, s)
    est = t.matcher.localize(problem)
    assert t._residual(t.matcher, problem, est) == pytest.approx(t.matcher.score(problem, est.pose), rel=1e-9)
    window = t.window.localize(problem)                 # the fit: one statistic for both windows
    assert t._residual(t.window, problem, window) == t._fit(problem, window)
    assert t._fit(problem, est) <= t._residual(t.matcher, problem, est)   # see-through only adds
