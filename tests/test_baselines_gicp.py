"""Baseline ``gicp``: recovers a known 0.3 m / 5° offset; its score prefers the truth; bad parameters."""

from __future__ import annotations

import numpy as np
import pytest
from _baseline_cases import OFFSETS, errors, make_problem

import tfloc

pytest.importorskip("small_gicp")
from baselines.gicp import GicpMatcher, stack_layers  # noqa: E402


@pytest.mark.parametrize(("direction", "sign"), OFFSETS)
def test_recovers_known_offset(direction: float, sign: float) -> None:
    problem, true = make_problem(direction, sign)
    est = tfloc.get_matcher("gicp").localize(problem)
    dist, orient = errors(est.pose, true)
    assert dist <= 0.02 and orient <= 0.5, (est, dist, orient)
    assert est.converged


def test_score_prefers_truth() -> None:
    problem, true = make_problem()
    matcher = GicpMatcher()
    assert matcher.score(problem, true) < matcher.score(problem, problem.initial)


def test_layers_stack_the_plane() -> None:
    pts = np.array([[1.0, 2.0], [3.0, 4.0]])
    out = stack_layers(pts, (-0.05, 0.0, 0.05))
    assert out.shape == (6, 3)
    assert np.allclose(out[:, :2], np.tile(pts, (3, 1)))
    assert np.allclose(out[:, 2], [-0.05, -0.05, 0.0, 0.0, 0.05, 0.05])


def test_registered_name_and_bad_parameters() -> None:
    matcher = tfloc.get_matcher("gicp")
    assert isinstance(matcher, GicpMatcher) and matcher.name == "gicp"
    for bad in ({"no_such_option": 1}, {"registration_type": "VGICP"}, {"gates": [0.5, 0.0]},
                {"layers": []}, {"map_spacing": -0.05}):
        with pytest.raises(tfloc.MatcherError, match="gicp"):
            tfloc.get_matcher("gicp", **bad)
