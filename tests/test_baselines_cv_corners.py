"""Baseline ``cv-corners``: too few corners is a no-answer; its hypotheses and corner refinement."""

from __future__ import annotations

import numpy as np
from _baseline_cases import make_problem
from tfloc.baselines._corner_match import best_hypothesis, pair_hypotheses
from tfloc.baselines._corner_refine import refine_corners
from tfloc.baselines.cv_corners import CvCornersMatcher

from tfloc import Problem


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
