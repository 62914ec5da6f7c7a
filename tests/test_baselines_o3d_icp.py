"""Baseline ``o3d-icp``: recovers a known 0.3 m / 5° offset; its score prefers the truth."""

from __future__ import annotations

import pytest
from _baseline_cases import OFFSETS, errors, make_problem
from tfloc.baselines.o3d_icp import Open3dIcpMatcher

import tfloc


@pytest.mark.parametrize(("direction", "sign"), OFFSETS)
def test_recovers_known_offset(direction: float, sign: float) -> None:
    problem, true = make_problem(direction, sign)
    est = tfloc.get_matcher("o3d-icp").localize(problem)
    dist, orient = errors(est.pose, true)
    assert dist <= 0.02 and orient <= 0.5, (est, dist, orient)
    assert est.converged


def test_score_prefers_truth() -> None:
    problem, true = make_problem()
    matcher = Open3dIcpMatcher()
    assert matcher.score(problem, true) < matcher.score(problem, problem.initial)


def test_registered_name_and_overrides() -> None:
    matcher = tfloc.get_matcher("o3d-icp")
    assert isinstance(matcher, Open3dIcpMatcher) and matcher.name == "o3d-icp"
    with pytest.raises(tfloc.MatcherError, match="no_such_option"):
        tfloc.get_matcher("o3d-icp", no_such_option=1)
