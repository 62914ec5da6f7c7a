"""``tf-best``: registered, the literal ``tf`` with only the documented readings changed, and it
recovers the pose on the test room."""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np

import tfloc
from tfloc import Pose
from tfloc.paper.best import BEST, TurningFunctionBestMatcher
from tfloc.paper.matcher import TfConfig

TRUE = Pose(3.0, 3.5, 0.4)


def test_registered_and_only_the_documented_readings_differ():
    m = tfloc.get_matcher("tf-best")
    assert isinstance(m, TurningFunctionBestMatcher) and m.name == "tf-best" and m.config == BEST
    changed = {f.name for f in fields(TfConfig) if getattr(BEST, f.name) != getattr(TfConfig(), f.name)}
    assert changed == {"err_norm", "spacing", "window", "orientation_step", "simplex_size",
                       "heading_clamp", "keep_best"}
    assert tfloc.get_matcher("tf").config == TfConfig()                  # tf stays literal
    assert tfloc.get_matcher("tf-best", seed=3).config.seed == 3         # overrides still work


def _offsets(d: float, deg: float):
    for k in range(4):  # four directions, alternating heading sign
        a = k * math.pi / 2 + 0.3
        yield Pose(TRUE.x + d * math.cos(a), TRUE.y + d * math.sin(a),
                   TRUE.theta + math.radians(deg) * (-1) ** k)


def test_tf_best_recovers_a_0p3m_5deg_offset(test_room, lms200):
    ranges = test_room.raycast(TRUE, lms200) + np.random.default_rng(0).normal(0, 0.01, lms200.n_beams)
    for k, init in enumerate(_offsets(0.3, 5.0)):
        est = tfloc.localize(test_room, lms200, ranges, init, matcher="tf-best")
        d, th = est.pose.distance_to(TRUE), abs(tfloc.angdiff(est.pose.theta, TRUE.theta))
        assert d < 0.10 and th < math.radians(1.0), f"direction {k}: {d:.3f} m, {math.degrees(th):.2f}°"
        # measured: 0.8–3.3 cm, ≤ 0.11°


def test_tf_best_keeps_its_heading_within_15deg_of_the_guess(test_room, lms200):
    ranges = test_room.raycast(TRUE, lms200) + np.random.default_rng(0).normal(0, 0.01, lms200.n_beams)
    for init in _offsets(1.0, 10.0):   # two of these four fail on position (measured)
        est = tfloc.localize(test_room, lms200, ranges, init, matcher="tf-best")
        assert abs(tfloc.angdiff(est.pose.theta, init.theta)) <= math.radians(15.0) + 1e-9
