"""Baseline ``csm-corr``: recovers a known 0.3 m / 5° offset; its score prefers the truth."""

from __future__ import annotations

import pytest
from _baseline_cases import OFFSETS, errors, make_problem
from tfloc.baselines.csm_corr import CorrelativeMatcher

import tfloc


@pytest.mark.parametrize(("direction", "sign"), OFFSETS)
def test_recovers_known_offset(direction: float, sign: float) -> None:
    problem, true = make_problem(direction, sign)
    est = tfloc.get_matcher("csm-corr").localize(problem)
    dist, orient = errors(est.pose, true)
    assert dist <= 0.02 and orient <= 0.5, (est, dist, orient)
    assert est.converged


def test_score_prefers_truth() -> None:
    problem, true = make_problem()
    matcher = CorrelativeMatcher()
    assert matcher.score(problem, true) < matcher.score(problem, problem.initial)


def test_registered_name_and_overrides() -> None:
    matcher = tfloc.get_matcher("csm-corr")
    assert isinstance(matcher, CorrelativeMatcher) and matcher.name == "csm-corr"
    with pytest.raises(tfloc.MatcherError, match="no_such_option"):
        tfloc.get_matcher("csm-corr", no_such_option=1)


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
