"""Pose interpolation to scan stamps: linear in x and y, shortest arc in heading, coverage."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tfloc.core.pose import angdiff
from tfloc.datasets.interpolate import interpolate_poses

T = np.array([0.0, 1.0, 2.0, 4.0])
P = np.array([[0.0, 0.0, 3.0], [1.0, 2.0, -3.0], [3.0, 2.0, 0.0], [3.0, 6.0, 1.0]])


def test_samples_midpoints_and_the_short_way_round() -> None:
    q, ok = interpolate_poses(T, P, np.array([0.0, 0.5, 1.5, 3.0, 4.0]))
    assert ok.all()
    np.testing.assert_allclose(q[0], P[0])
    np.testing.assert_allclose(q[4], P[3])
    np.testing.assert_allclose(q[1, :2], [0.5, 1.0])
    # 3 rad → -3 rad is 0.283 rad across ±π, not 6 rad through 0
    assert abs(angdiff(q[1, 2], math.pi)) < 1e-12
    np.testing.assert_allclose(q[2], [2.0, 2.0, -1.5])
    np.testing.assert_allclose(q[3], [3.0, 4.0, 0.5])


def test_coverage_and_gaps() -> None:
    q, ok = interpolate_poses(T, P, np.array([-0.1, 4.1, 3.0, 1.0, 2.0]), max_gap=1.5)
    assert ok.tolist() == [False, False, False, True, True]  # outside, outside, inside a 2 s gap
    assert np.isnan(q[:3]).all() and np.isfinite(q[3:]).all()
    q, ok = interpolate_poses(T[:1], P[:1], np.array([0.0, 0.1]))
    assert ok.tolist() == [True, False]
    q, ok = interpolate_poses(T[:0], P[:0], np.array([0.0]))
    assert not ok.any()


@settings(max_examples=60, deadline=None)
@given(st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi), st.floats(0.0, 1.0))
def test_heading_moves_monotonically_along_the_shorter_arc(a: float, b: float, w: float) -> None:
    q, ok = interpolate_poses(np.array([0.0, 1.0]), np.array([[0, 0, a], [0, 0, b]]), np.array([w]))
    assert ok[0]
    d = angdiff(b, a)
    assert abs(angdiff(q[0, 2], a) - w * d) < 1e-9
    assert -math.pi <= q[0, 2] < math.pi
