"""Baseline ``csm-corr``: a long-range laser keeps its likelihood field small."""

from __future__ import annotations

from _baseline_cases import errors, make_problem
from tfloc.baselines.csm_corr import CorrelativeMatcher


def test_long_range_laser_keeps_the_field_small() -> None:
    from tfloc import LaserSpec, Problem

    problem, true = make_problem()
    laser = LaserSpec.from_degrees(80.0, 180.0, 1.0)
    ranges = problem.map.raycast(true, laser)
    long_range = Problem(problem.map, laser, ranges, problem.initial)
    matcher = CorrelativeMatcher()
    est = matcher.localize(long_range)
    dist, orient = errors(est.pose, true)
    assert dist <= 0.02 and orient <= 0.5
    h, w = matcher._field(long_range).shape
    assert h * w * matcher.config.resolution**2 < 40.0 * 40.0  # not (10 m + 2·80 m)²
