"""bnb-global: Cartographer's branch and bound (bounds, exactness, a global find, parameters)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tfloc.baselines._bnb_kernels import (
    angular_step,
    branch_and_bound,
    candidate_sum,
    discretize,
    exhaustive,
    pyramid,
)
from tfloc.baselines.bnb_global import BranchAndBoundGlobalMatcher, probability_grid

import tfloc
from tfloc.core.matcher import check_solvable, get_matcher, solves_global
from tfloc.core.pose import Pose, angdiff
from tfloc.errors import ParameterError


def _random_case(seed: int, depth: int = 4, h: int = 37, w: int = 45, n_rot: int = 3, n_pts: int = 25):
    rng = np.random.default_rng(seed)
    base = rng.integers(0, 256, size=(h, w)).astype(np.uint8)
    grids = pyramid(base, depth)
    offsets = rng.integers(-12, 13, size=(n_rot, n_pts, 2)).astype(np.int32)
    return base, grids, (1 << (depth - 1)) - 1, offsets


def test_pyramid_levels_hold_the_window_maxima() -> None:
    base, grids, pad, _ = _random_case(0)
    H, W = base.shape
    padded = np.zeros((H + 2 * pad, W + 2 * pad), dtype=np.uint8)
    padded[pad:pad + H, pad:pad + W] = base
    for h in range(grids.shape[0]):
        w = 1 << h
        for y, x in [(0, 0), (pad - 3, pad + 5), (pad + H - 2, pad + W - 1), (10, 20)]:
            assert grids[h, y, x] == padded[y:y + w, x:x + w].max()


@pytest.mark.parametrize("seed", range(5))
def test_every_leaf_scores_at_most_its_ancestors_bound(seed) -> None:
    _, grids, pad, offsets = _random_case(seed)
    rng = np.random.default_rng(100 + seed)
    for _ in range(40):
        h = int(rng.integers(1, grids.shape[0]))
        k, x, y = int(rng.integers(0, offsets.shape[0])), int(rng.integers(-8, 45)), int(rng.integers(-8, 37))
        bound = candidate_sum(grids, pad, offsets, k, x, y, h)
        w = 1 << h
        leaves = [candidate_sum(grids, pad, offsets, k, x + i, y + j, 0) for i in range(w) for j in range(w)]
        assert max(leaves) <= bound
        for i in (0, w // 2):  # and every child's bound is at most its parent's
            for j in (0, w // 2):
                assert candidate_sum(grids, pad, offsets, k, x + i, y + j, h - 1) <= bound


@pytest.mark.parametrize("seed", range(4))
def test_branch_and_bound_finds_the_exhaustive_best_on_random_grids(seed) -> None:
    _, grids, pad, offsets = _random_case(seed, n_rot=4)
    bk, bx, by, best = exhaustive(grids, pad, offsets, 0, 44, 0, 36)
    hk, hx, hy, hs, count, scored = branch_and_bound(grids, pad, offsets, 0, 44, 0, 36, 0.0, 1, 0.0, 0)
    assert count == 1 and hs[0] == best
    assert candidate_sum(grids, pad, offsets, int(hk[0]), int(hx[0]), int(hy[0]), 0) == best
    assert scored < offsets.shape[0] * 45 * 37  # it pruned


def test_branch_and_bound_finds_the_exhaustive_best_on_a_small_map(test_room, lms200) -> None:
    m = BranchAndBoundGlobalMatcher()
    grid = probability_grid(test_room, 0.05, 0.05, 7)
    truth = Pose(4.1, 2.3, 0.7)
    pts = lms200.to_points(test_room.raycast(truth, lms200))
    thetas = truth.theta + np.radians(np.arange(-12, 13, 3.0))  # a few headings keep brute force quick
    offsets = discretize(pts, thetas, 0.05)
    (x0, x1), (y0, y1) = grid.x_range, grid.y_range
    bk, bx, by, best = exhaustive(grid.grids, grid.pad, offsets, x0, x1, y0, y1)
    hk, hx, hy, hs, count, _ = branch_and_bound(grid.grids, grid.pad, offsets, x0, x1, y0, y1, 0.0, 3,
                                                0.5 / 0.05, 3)
    assert count >= 1 and hs[0] == best
    # the best is at the truth (to a cell and the heading step)
    wx, wy = grid.world(np.array([hx[0]]), np.array([hy[0]]))
    assert math.hypot(wx[0] - truth.x, wy[0] - truth.y) < 0.08 and int(hk[0]) == 4
    assert m.name == "bnb-global"


def test_distinct_hypotheses_are_ranked_and_apart(test_room, lms200) -> None:
    grid = probability_grid(test_room, 0.05, 0.05, 7)
    pts = lms200.to_points(test_room.raycast(Pose(6.0, 6.5, -2.0), lms200))
    thetas = np.radians(np.arange(-180.0, 180.0, 2.0))
    offsets = discretize(pts, thetas, 0.05)
    (x0, x1), (y0, y1) = grid.x_range, grid.y_range
    hk, hx, hy, hs, count, _ = branch_and_bound(grid.grids, grid.pad, offsets, x0, x1, y0, y1, 0.0, 5, 10.0, 5)
    assert count == 5 and np.all(np.diff(hs[:count]) <= 0)
    for a in range(count):
        for b in range(a):
            dk = abs(int(hk[a]) - int(hk[b]))
            dk = min(dk, len(thetas) - dk)
            assert math.hypot(hx[a] - hx[b], hy[a] - hy[b]) > 10.0 or dk > 5


def test_angular_step_follows_eq_7() -> None:
    step = angular_step(10.0, 0.05)
    assert step == pytest.approx(0.999 * math.acos(1 - 0.05 ** 2 / 200.0))
    assert 10.0 * step == pytest.approx(0.05, rel=0.01)  # the farthest point moves one cell
    assert angular_step(0.0, 0.05) == angular_step(0.15, 0.05)  # floored at 3 cells


@pytest.mark.parametrize("truth", [Pose(3.0, 3.5, 0.3), Pose(8.8, 2.0, 2.5), Pose(5.5, 6.8, -1.9)])
def test_a_simulated_scan_is_found_over_the_whole_room(test_room, lms200, truth) -> None:
    m = get_matcher("bnb-global")
    assert solves_global(m)
    rng = np.random.default_rng(7)
    ranges = test_room.raycast(truth, lms200) + rng.normal(0.0, 0.01, lms200.n_beams)
    problem = tfloc.Problem(test_room, lms200, ranges, None)
    check_solvable(m, problem)  # no InvalidProblemError: it takes global problems
    est = m.localize(problem)
    assert est.info.get("status") != "no-answer"
    assert est.pose.distance_to(truth) < 0.10 and abs(angdiff(est.pose.theta, truth.theta)) < math.radians(2)
    assert est.hypotheses[0] == est.pose and 1 <= len(est.hypotheses) <= 5
    assert m.score(problem, est.pose) <= m.score(problem, Pose(truth.x + 0.5, truth.y, truth.theta))


def test_local_problem_searches_the_window(test_room, lms200) -> None:
    truth = Pose(3.0, 3.5, 0.3)
    problem = tfloc.Problem(test_room, lms200, test_room.raycast(truth, lms200), Pose(3.6, 3.1, 0.5))
    est = get_matcher("bnb-global", linear_search_window=1.0).localize(problem)
    assert est.pose.distance_to(truth) < 0.10 and abs(angdiff(est.pose.theta, truth.theta)) < math.radians(2)


def test_no_pose_above_the_threshold_is_no_answer(test_room, lms200) -> None:
    ranges = np.full(lms200.n_beams, np.inf)
    ranges[::10] = 3.3  # an arc of points that fits nowhere well
    est = get_matcher("bnb-global", min_score=0.95).localize(tfloc.Problem(test_room, lms200, ranges, None))
    assert est.info["status"] == "no-answer" and not est.pose.is_finite()


@pytest.mark.parametrize("key, value, message", [
    ("min_score", 1.5, r"min_score must be \[0, 1\], got 1.5"),
    ("branch_and_bound_depth", 0, r"branch_and_bound_depth must be >= 1"),
    ("branch_and_bound_depth", 20, r"branch_and_bound_depth must be ≤ 12"),
    ("angular_search_window_deg", 270.0, r"angular_search_window_deg must be ≤ 180"),
    ("resolution", -0.05, r"resolution must be > 0"),
    ("hypotheses", 0, r"hypotheses must be >= 1"),
    ("min_scor", 0.5, r"unknown parameter\(s\) min_scor"),
])
def test_bad_parameters_are_rejected(key, value, message) -> None:
    with pytest.raises(ParameterError, match=message):
        get_matcher("bnb-global", **{key: value})


def test_adaptive_voxel_filter_keeps_enough_points() -> None:
    from tfloc.baselines.bnb_global import adaptive_voxel_filter, voxel_filter

    rng = np.random.default_rng(3)
    pts = rng.uniform(-20, 20, size=(361, 2))
    out = adaptive_voxel_filter(pts, 0.9, 100)
    assert 100 <= len(out) < 361 and set(map(tuple, out)) <= set(map(tuple, pts))
    assert len(voxel_filter(pts, 0.9 * 1.2)) < 361  # a coarser edge would keep fewer
    few = pts[:80]
    assert adaptive_voxel_filter(few, 0.9, 100) is few  # at most min_num_points: kept whole
    dense = np.column_stack((np.linspace(0, 1, 400), np.zeros(400)))  # 400 points on 1 m
    assert len(adaptive_voxel_filter(dense, 0.9, 100)) >= 100
