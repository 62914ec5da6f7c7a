"""Every baseline matcher: recovers a known 0.3 m / 5° offset in the test room within 2 cm / 0.5°,
its own score prefers the truth, and it is registered under its name with checked parameters.
Matcher-specific tests stay in ``test_baselines_<name>.py``."""

from __future__ import annotations

import pytest
from _baseline_cases import OFFSETS, errors, make_problem

import tfloc

#: Registered name → class path of every baseline (a new baseline adds one line).
BASELINES = {
    "o3d-icp": "tfloc.baselines.o3d_icp:Open3dIcpMatcher",
    "kiss-icp": "tfloc.baselines.kiss_icp:KissIcpMatcher",
    "cv-corners": "tfloc.baselines.cv_corners:CvCornersMatcher",
    "csm-corr": "tfloc.baselines.csm_corr:CorrelativeMatcher",
    "gicp": "tfloc.baselines.gicp:GicpMatcher",
    "karto": "tfloc.baselines.karto:KartoMatcher",
}
#: Optional libraries: a baseline whose library is not installed is skipped here (the registry
#: tests check that it then fails with one line and the others still run).
OPTIONAL = {"gicp": "small_gicp", "karto": "karto_scanmatcher"}


def _needs(name: str) -> None:
    if name in OPTIONAL:
        pytest.importorskip(OPTIONAL[name])


@pytest.mark.parametrize("name", BASELINES)
@pytest.mark.parametrize(("direction", "sign"), OFFSETS)
def test_recovers_known_offset(name: str, direction: float, sign: float) -> None:
    _needs(name)
    problem, true = make_problem(direction, sign)
    est = tfloc.get_matcher(name).localize(problem)
    dist, orient = errors(est.pose, true)
    assert dist <= 0.02 and orient <= 0.5, (est, dist, orient)
    assert est.converged


@pytest.mark.parametrize("name", BASELINES)
def test_score_prefers_truth(name: str) -> None:
    _needs(name)
    problem, true = make_problem()
    matcher = tfloc.get_matcher(name)
    assert matcher.score(problem, true) < matcher.score(problem, problem.initial)


@pytest.mark.parametrize("name", BASELINES)
def test_registered_name_and_parameters(name: str) -> None:
    _needs(name)
    matcher = tfloc.get_matcher(name)
    module, _, cls = BASELINES[name].partition(":")
    assert type(matcher).__module__ == module and type(matcher).__name__ == cls
    assert matcher.name == name
    with pytest.raises(tfloc.errors.ParameterError, match=f"{name}.*no_such_option"):
        tfloc.get_matcher(name, no_such_option=1)
