"""Every baseline matcher (the registry's matchers whose module is in ``baselines/``): recovers a
known 0.3 m / 5° offset in the test room within 2 cm / 0.5° from three directions. The contract
every matcher meets (names, parameters, score, tiny scans) is ``test_matchers.py``;
matcher-specific tests stay in ``tests/baselines/test_<name>.py``."""

from __future__ import annotations

import pytest
from _baseline_cases import OFFSETS, errors, make_problem
from _registry import BASELINES, kind, single_scan

import tfloc


@pytest.mark.parametrize("name", BASELINES)
@pytest.mark.parametrize(("direction", "sign"), OFFSETS)
def test_recovers_known_offset(name: str, direction: float, sign: float) -> None:
    matcher = single_scan(name)
    problem, true = make_problem(direction, sign)
    if kind(matcher) == "global":
        problem = tfloc.Problem(problem.map, problem.laser, problem.ranges, None)
    est = matcher.localize(problem)
    dist, orient = errors(est.pose, true)
    assert dist <= 0.02 and orient <= 0.5, (est, dist, orient)
    assert est.converged
