"""The matcher contract, for every registered matcher (found in the registry: a new matcher is
one module declaring it, or a third party's entry point, and these tests cover it without editing
any test file).

A single-scan matcher answers the test room's known 0.3 m / 5° offset with a finite pose that
stays within a metre of the truth (a sanity bound, not an accuracy test: the paper's faithful
``tf`` ends 0.45 m off here; each baseline's accuracy is ``test_baselines.py``), scores the truth
below the guess, refuses unknown parameters by name, and survives a scan of one return; a local
matcher given a global problem is refused before it runs. Run as a tracker along a short
straight run, it stays within a metre too."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _baseline_cases import make_problem
from _registry import NAMES, build, kind, single_scan

import tfloc
from tfloc.core.matcher import check_solvable
from tfloc.errors import InvalidProblemError, ParameterError

#: the sanity bound of these tests (metres)
SANE_M = 1.0


@pytest.mark.parametrize("name", NAMES)
def test_name_and_unknown_parameter(name: str) -> None:
    matcher = build(name)
    assert matcher.name == name
    with pytest.raises(ParameterError, match=f"{name}.*no_such_option"):
        tfloc.get_matcher(name, no_such_option=1)


@pytest.mark.parametrize("name", NAMES)
def test_answers_and_improves_on_the_guess(name: str) -> None:
    matcher = single_scan(name)
    problem, true = make_problem()
    if kind(matcher) == "global":
        problem = tfloc.Problem(problem.map, problem.laser, problem.ranges, None)
    est = matcher.localize(problem)
    assert est.pose.is_finite()
    assert est.pose.distance_to(true) < SANE_M, est
    if kind(matcher) == "global":
        assert est.hypotheses and est.hypotheses[0] == est.pose


@pytest.mark.parametrize("name", NAMES)
def test_score_prefers_truth(name: str) -> None:
    matcher = single_scan(name)
    if not callable(getattr(matcher, "score", None)):
        pytest.skip("a matcher without an objective (e.g. odometry)")
    problem, true = make_problem()
    assert math.isfinite(matcher.score(problem, true))
    assert matcher.score(problem, true) < matcher.score(problem, problem.initial)


@pytest.mark.parametrize("name", NAMES)
def test_a_global_problem_is_refused_by_a_local_matcher(name: str) -> None:
    matcher = single_scan(name)
    problem, _ = make_problem()
    glob = tfloc.Problem(problem.map, problem.laser, problem.ranges, None)
    if kind(matcher) == "local":
        with pytest.raises(InvalidProblemError, match="global problem"):
            check_solvable(matcher, glob)
    else:
        check_solvable(matcher, glob)


@pytest.mark.parametrize("name", NAMES)
def test_a_scan_of_one_return_does_not_crash(name: str) -> None:
    matcher = single_scan(name)
    problem, _ = make_problem()
    ranges = np.full_like(problem.ranges, np.inf)
    ranges[80] = problem.ranges[80]
    tiny = tfloc.Problem(problem.map, problem.laser, ranges, problem.initial)
    est = matcher.localize(tiny)
    assert est.pose.is_finite()


@pytest.mark.parametrize("name", NAMES)
def test_tracker_follows_a_straight_run(name: str) -> None:
    from tfloc.core.tracker import as_tracker

    matcher = build(name)
    if kind(matcher) == "global":
        pytest.skip("a global matcher is not run as a tracker")
    if callable(getattr(matcher, "run_batch", None)):
        pytest.skip("an external program answers a whole sequence at once (tests/baselines/test_mrpt_pf.py)")
    problem, true = make_problem()
    tracker = as_tracker(matcher)
    tracker.start(problem.map, problem.laser, true)
    step = tfloc.Pose(0.05, 0.0, 0.0)
    pose = true
    rng = np.random.default_rng(3)
    for k in range(5):
        pose = pose.compose(step)
        ranges = problem.map.raycast(pose, problem.laser) + rng.normal(0.0, 0.01, problem.laser.n_beams)
        est = tracker.step(ranges, step, float(k + 1))
        assert est.pose.is_finite()
    assert est.pose.distance_to(pose) < SANE_M, (est.pose, pose)
