"""End to end: the ``tf`` matcher with the compiled kernels (the fused cost evaluation of
tfloc/_tf_kernels.py) gives the same answers as with the previous implementations run step by
step (brute-force raycast, numpy ShortStraw candidates / turning function / matching, kept as
oracles in tests/*/test_kernels_*.py)."""

from __future__ import annotations

import math

import _tf_oracles
import numpy as np
import pytest
from _tf_oracles import step_by_step_tf
from test_kernels_corners import shortstraw_ref
from test_kernels_turning import match_ref, turning_function_ref

import tfloc.maps.vector
import tfloc.paper.shape
from tfloc import Pose, Problem
from tfloc.maps._raycast import raycast_segments_bruteforce
from tfloc.paper.matcher import TfConfig, TurningFunctionMatcher

TRUE = Pose(3.0, 3.5, 0.4)


def _problems(test_room, lms200):
    ranges = test_room.raycast(TRUE, lms200) + np.random.default_rng(0).normal(0, 0.01, lms200.n_beams)
    for k, (d, dth) in enumerate([(0.3, 5.0), (0.6, -8.0)]):
        a = 0.3 + 2.0 * k
        init = Pose(TRUE.x + d * math.cos(a), TRUE.y + d * math.sin(a), TRUE.theta + math.radians(dth))
        yield Problem(test_room, lms200, ranges, init)


@pytest.mark.parametrize("config", [TfConfig(), TfConfig(spacing=0.25, window=2)],
                         ids=["paper", "fine"])
def test_localize_matches_the_reference_pipeline(test_room, lms200, config, monkeypatch):
    matcher = TurningFunctionMatcher(config)
    problems = list(_problems(test_room, lms200))
    fast = [matcher.localize(p) for p in problems]
    with monkeypatch.context() as mp:
        step_by_step_tf(mp)  # step by step, through the oracles below
        mp.setattr(tfloc.maps.vector, "raycast_segments", raycast_segments_bruteforce)
        mp.setattr(tfloc.paper.shape, "shortstraw", shortstraw_ref)
        mp.setattr(tfloc.paper.shape, "turning_function", turning_function_ref)
        mp.setattr(_tf_oracles, "match", lambda real, virtual: match_ref(real, virtual)[0])
        ref = [matcher.localize(p) for p in problems]
    for f, r in zip(fast, ref, strict=True):
        np.testing.assert_allclose(f.pose.as_array(), r.pose.as_array(), rtol=0, atol=1e-9)
        assert (f.converged, f.iterations, f.evaluations) == (r.converged, r.iterations, r.evaluations)
        assert f.info["err"] == pytest.approx(r.info["err"], abs=1e-9)
