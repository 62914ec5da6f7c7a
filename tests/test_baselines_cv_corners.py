"""Baseline ``cv-corners``: recovers a known 0.3 m / 5° offset; its score prefers the truth."""

from __future__ import annotations

import numpy as np
import pytest
from _baseline_cases import OFFSETS, errors, make_problem
from tfloc.baselines._corner_match import best_hypothesis, pair_hypotheses
from tfloc.baselines._corner_refine import refine_corners
from tfloc.baselines.cv_corners import CvCornersMatcher

import tfloc
from tfloc import Problem


@pytest.mark.parametrize(("direction", "sign"), OFFSETS)
def test_recovers_known_offset(direction: float, sign: float) -> None:
    problem, true = make_problem(direction, sign)
    est = tfloc.get_matcher("cv-corners").localize(problem)
    dist, orient = errors(est.pose, true)
    assert dist <= 0.02 and orient <= 0.5, (est, dist, orient)
    assert est.converged


def test_score_prefers_truth() -> None:
    problem, true = make_problem()
    matcher = CvCornersMatcher()
    assert matcher.score(problem, true) < matcher.score(problem, problem.initial)


def test_registered_name_and_overrides() -> None:
    matcher = tfloc.get_matcher("cv-corners")
    assert isinstance(matcher, CvCornersMatcher) and matcher.name == "cv-corners"
    with pytest.raises(tfloc.MatcherError, match="no_such_option"):
        tfloc.get_matcher("cv-corners", no_such_option=1)


def test_fewer_than_two_corners_is_a_no_answer() -> None:
    problem, _ = make_problem()
    ranges = np.full_like(problem.ranges, np.inf)
    ranges[90] = 3.0  # one return: one point, no corner pair
    lonely = Problem(problem.map, problem.laser, ranges, problem.initial)
    est = CvCornersMatcher().localize(lonely)
    assert not est.converged
    assert est.info["status"] == "no-answer"
    assert est.pose == problem.initial


def test_pair_hypotheses_recover_a_rigid_transform() -> None:
    rng = np.random.default_rng(3)
    a = rng.uniform(-4, 4, (8, 2))
    theta, t = 0.2, np.array([0.7, -0.4])
    c, s = np.cos(theta), np.sin(theta)
    b = a @ np.array([[c, -s], [s, c]]).T + t
    b = np.vstack((b[2:], rng.uniform(-4, 4, (3, 2))))  # two corners unseen, three clutter
    hyp = pair_hypotheses(a, b, 0.05, 0.5, np.radians(25), 4.0)
    h, partner, _ = best_hypothesis(a, b, hyp, 0.05)
    assert abs(hyp.theta[h] - theta) < 1e-9 and np.allclose(hyp.t[h], t)
    assert (partner >= 0).sum() == 6


def test_refine_corners_moves_a_corner_onto_the_wall_intersection() -> None:
    rng = np.random.default_rng(5)
    wall1 = np.column_stack((np.linspace(0, 2, 40), np.zeros(40)))
    wall2 = np.column_stack((np.full(40, 2.0), np.linspace(0, 2, 40)))
    pts = np.vstack((wall1, wall2[1:])) + rng.normal(0, 0.01, (79, 2))
    rough = np.array([[0.0, 0.0], [1.96, 0.03], [2.0, 2.0]])
    fine = refine_corners(rough, pts)
    assert np.linalg.norm(fine[1] - (2.0, 0.0)) < 0.01 < np.linalg.norm(rough[1] - (2.0, 0.0))
    assert np.allclose(fine[[0, 2]], rough[[0, 2]])
