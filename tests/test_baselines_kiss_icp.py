"""Baseline ``kiss-icp``: recovers a known 0.3 m / 5° offset; its score prefers the truth."""

from __future__ import annotations

import pytest
from _baseline_cases import OFFSETS, errors, make_problem
from tfloc.baselines.kiss_icp import KissIcpMatcher

import tfloc


@pytest.mark.parametrize(("direction", "sign"), OFFSETS)
def test_recovers_known_offset(direction: float, sign: float) -> None:
    problem, true = make_problem(direction, sign)
    est = tfloc.get_matcher("kiss-icp").localize(problem)
    dist, orient = errors(est.pose, true)
    assert dist <= 0.02 and orient <= 0.5, (est, dist, orient)
    assert est.converged


def test_score_prefers_truth() -> None:
    problem, true = make_problem()
    matcher = KissIcpMatcher()
    assert matcher.score(problem, true) < matcher.score(problem, problem.initial)


def test_registered_name_and_overrides() -> None:
    matcher = tfloc.get_matcher("kiss-icp")
    assert isinstance(matcher, KissIcpMatcher) and matcher.name == "kiss-icp"
    with pytest.raises(tfloc.MatcherError, match="no_such_option"):
        tfloc.get_matcher("kiss-icp", no_such_option=1)
