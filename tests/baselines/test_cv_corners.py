"""Baseline ``cv-corners``: too few corners is a no-answer; its hypotheses, search and corner refinement."""

from __future__ import annotations

import numpy as np
import pytest
from _baseline_cases import make_problem
from tfloc.baselines._corner_kernels import inlier_counts
from tfloc.baselines._corner_match import best_hypothesis, pair_hypotheses, search_hypotheses
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


def _all_pairs_reference(a: np.ndarray, b: np.ndarray, tol: float, min_len: float, max_angle: float,
                         max_shift: float) -> set[tuple[float, float, float]]:
    """The former all-ordered-pairs search, written plainly: every hypothesis, rounded to 1e-9."""
    out = set()
    for i in range(len(a)):
        for j in range(len(a)):
            for k in range(len(b)):
                for m in range(len(b)):
                    if i == j or k == m:
                        continue
                    va, vb = a[j] - a[i], b[m] - b[k]
                    la, lb = np.hypot(*va), np.hypot(*vb)
                    if la < min_len or lb < min_len or abs(la - lb) > tol:
                        continue
                    th = (np.arctan2(vb[1], vb[0]) - np.arctan2(va[1], va[0]) + np.pi) % (2 * np.pi) - np.pi
                    c, s = np.cos(th), np.sin(th)
                    ma, mb = a[i] + 0.5 * va, b[k] + 0.5 * vb
                    t = mb - np.array([c * ma[0] - s * ma[1], s * ma[0] + c * ma[1]])
                    if abs(th) <= max_angle and np.hypot(*t) <= max_shift:
                        out.add((round(th, 9), round(t[0], 9), round(t[1], 9)))
    return out


def test_pair_hypotheses_are_the_distinct_all_pairs_hypotheses() -> None:
    """Taking each pair of ``a`` once loses no hypothesis: the reversed pair onto the reversed
    pair of ``b`` is the same transform. The set equals the former ordered × ordered search's."""
    rng = np.random.default_rng(11)
    a = rng.uniform(-3, 3, (9, 2))
    b = np.vstack((a[:7] @ np.array([[0.98, -0.2], [0.2, 0.98]]).T + (0.3, -0.2), rng.uniform(-3, 3, (3, 2))))
    hyp = pair_hypotheses(a, b, 0.15, 0.5, np.radians(25), 4.0)
    got = {(round(th, 9), round(x, 9), round(y, 9)) for th, (x, y) in zip(hyp.theta, hyp.t, strict=True)}
    assert len(got) == hyp.theta.size > 10  # no duplicates left
    assert got == _all_pairs_reference(a, b, 0.15, 0.5, np.radians(25), 4.0)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("tol", [0.05, 0.4, 1.5])
def test_inlier_counts_match_a_dense_reference(seed: int, tol: float) -> None:
    """The grid-based numba count equals mutual nearest neighbours on the full distance matrix,
    also for moved corners beyond the virtual corners' extent."""
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-3, 3, (12, 2)), rng.uniform(-3, 3, (10, 2))
    hyp = pair_hypotheses(a, b, 0.3, 0.5, np.radians(25), 4.0)
    count, resid = inlier_counts(hyp.theta, hyp.t, a, b, tol)
    for h in range(hyp.theta.size):
        c, s = np.cos(hyp.theta[h]), np.sin(hyp.theta[h])
        moved = a @ np.array([[c, -s], [s, c]]).T + hyp.t[h]
        d = np.linalg.norm(moved[:, None] - b[None], axis=-1)
        pairs = [(i, k) for i in range(len(a)) for k in [d[i].argmin()] if d[:, k].argmin() == i and d[i, k] <= tol]
        assert count[h] == len(pairs)
        assert resid[h] == pytest.approx(sum(d[i, k] for i, k in pairs))


def test_adaptive_search_finds_the_best_match_of_the_exhaustive_search() -> None:
    """Drawing pairs in random order with the adaptive stop (and without it) ends on a match with
    as many inliers as scoring every hypothesis, and scores fewer hypotheses with the stop."""
    rng = np.random.default_rng(8)
    a = rng.uniform(-5, 5, (40, 2))
    theta, t = 0.15, np.array([0.6, -0.3])
    c, s = np.cos(theta), np.sin(theta)
    b = np.vstack((a[:30] @ np.array([[c, -s], [s, c]]).T + t + rng.normal(0, 0.01, (30, 2)),
                   rng.uniform(-5, 5, (15, 2))))
    hyp = pair_hypotheses(a, b, 0.15, 0.5, np.radians(25), 4.0, max_hypotheses=10**9)
    _, partner, _ = best_hypothesis(a, b, hyp, 0.2)
    full = search_hypotheses(a, b, 0.15, 0.5, np.radians(25), 4.0, 0.2, 1.0, 10**9)
    fast = search_hypotheses(a, b, 0.15, 0.5, np.radians(25), 4.0, 0.2, 0.999, 10**9)
    assert full.scored == hyp.theta.size and full.inliers == (partner >= 0).sum() >= 30
    assert fast.inliers == full.inliers and fast.scored < hyp.theta.size / 10
    assert abs(fast.theta - theta) < 0.01 and np.linalg.norm(fast.t - t) < 0.05
