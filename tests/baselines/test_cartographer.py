"""``cartographer-local``: Ceres' bicubic interpolation against its formula, the residuals at the
true pose, the filters' choice of points, the real-time CSM's window, and convergence along a
sequence from small offsets (Cartographer's priors pull towards the prediction, so one scan
corrects part of an offset and the next ones the rest)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _baseline_cases import TRUE_POSE, errors, make_problem
from tfloc.baselines.cartographer import _csm
from tfloc.baselines.cartographer._filters import _MinstdRand0, adaptive_voxel_filter, voxel_filter
from tfloc.baselines.cartographer._grid import MIN_PROBABILITY, bicubic, cost_at, probability_grid

import tfloc
from tfloc import Pose, Problem
from tfloc.core.tracker import as_tracker


def _keys(t: np.ndarray) -> np.ndarray:
    """The cubic convolution kernel with a = −½ (Catmull–Rom), the closed form of Ceres' spline."""
    t = np.abs(t)
    return np.where(t <= 1, 1.5 * t**3 - 2.5 * t**2 + 1,
                    np.where(t < 2, -0.5 * t**3 + 2.5 * t**2 - 4 * t + 2, 0.0))


def _direct(values: np.ndarray, row: float, col: float, outside: float) -> float:
    H, W = values.shape
    total = 0.0
    for r in range(int(math.floor(row)) - 1, int(math.floor(row)) + 3):
        for c in range(int(math.floor(col)) - 1, int(math.floor(col)) + 3):
            v = values[r, c] if 0 <= r < H and 0 <= c < W else outside
            total += v * _keys(np.array(row - r)) * _keys(np.array(col - c))
    return float(total)


def test_bicubic_is_the_catmull_rom_formula_with_its_derivatives() -> None:
    rng = np.random.default_rng(1)
    values = rng.uniform(0.1, 0.9, (7, 9))
    rows, cols = rng.uniform(-2.5, 8.5, 200), rng.uniform(-2.5, 10.5, 200)
    f, dr, dc = bicubic(values, rows, cols, 0.9)
    assert np.allclose(f, [_direct(values, r, c, 0.9) for r, c in zip(rows, cols, strict=True)], atol=1e-12)
    h = 1e-6
    assert np.allclose(dr, (bicubic(values, rows + h, cols, 0.9)[0] - bicubic(values, rows - h, cols, 0.9)[0]) / (2 * h),
                       atol=1e-5)
    assert np.allclose(dc, (bicubic(values, rows, cols + h, 0.9)[0] - bicubic(values, rows, cols - h, 0.9)[0]) / (2 * h),
                       atol=1e-5)
    i, j = np.meshgrid(np.arange(9), np.arange(7))  # at cell centres: the cell's own value
    assert np.allclose(bicubic(values, j.ravel().astype(float), i.ravel().astype(float), 0.9)[0], values.ravel())
    assert np.allclose(bicubic(values, np.array([50.0]), np.array([-40.0]), 0.9)[0], 0.9)  # far off: padding


def test_residuals_at_the_true_pose_are_those_of_wall_cells() -> None:
    problem, true = make_problem()
    m = tfloc.get_matcher("cartographer-local")
    grid = probability_grid(problem.map, m.config.occupied_probability)
    pts = m._points(problem)
    at_true, _, _ = cost_at(grid, true.transform(pts))
    off, _, _ = cost_at(grid, true.compose(Pose(0.1, 0.1, 0.0)).transform(pts))
    assert np.median(at_true) < 0.15 and np.median(off) > 0.5  # 1 − 0.9 on the walls, 1 − 0.1 beside them
    assert np.all((at_true >= 0.1 - 0.2) & (at_true <= 0.9 + 0.2))  # Catmull–Rom over- and undershoots a little
    # from the truth as prediction the priors are zero and the solution stays put
    est = m.localize(Problem(problem.map, problem.laser, problem.ranges, true))
    dist, orient = errors(est.pose, true)
    assert dist < 0.01 and orient < 0.2 and est.converged


@pytest.mark.parametrize("params", [{}, {"use_online_correlative_scan_matching": True}])
@pytest.mark.parametrize("offset", [(0.04, 0.0, 1.5), (-0.03, 0.05, -2.0), (0.06, -0.04, 2.5)])
def test_converges_along_a_sequence_from_small_offsets(params: dict, offset: tuple) -> None:
    problem, true = make_problem()
    m = tfloc.get_matcher("cartographer-local", **params)
    start = true.compose(Pose(offset[0], offset[1], math.radians(offset[2])))
    one = m.localize(Problem(problem.map, problem.laser, problem.ranges, start))
    assert errors(one.pose, true)[0] <= errors(start, true)[0] + 1e-3
    assert errors(one.pose, true)[1] < errors(start, true)[1]  # one scan corrects part of it
    tracker = as_tracker(m)
    tracker.start(problem.map, problem.laser, start)
    rng = np.random.default_rng(5)
    for k in range(40):  # the robot stands still: every scan from the last estimate
        ranges = problem.map.raycast(true, problem.laser) + rng.normal(0.0, 0.01, problem.laser.n_beams)
        est = tracker.step(ranges, Pose(), float(k))
    dist, orient = errors(est.pose, true)
    assert dist < 0.01 and orient < 0.3, (est.pose, dist, orient)


def test_the_filters_keep_cartographers_points() -> None:
    rng = _MinstdRand0()  # std::minstd_rand0's first outputs from its default seed
    assert [rng() for _ in range(3)] == [16807, 282475249, 1622650073]
    pts = np.array([[0.0, 0.0], [0.01, 0.0], [0.3, 0.0], [0.31, 0.004], [1.0, 1.0]])
    kept = voxel_filter(pts, 0.025)
    assert len(kept) == 3 and 4 in kept and list(kept) == sorted(kept)
    line = np.column_stack((np.linspace(0.5, 20.0, 400), np.zeros(400)))
    assert len(adaptive_voxel_filter(line[:150], 0.5, 200, 50.0)) == 150  # few points: all kept
    dense = adaptive_voxel_filter(line, 0.5, 200, 50.0)
    assert 200 <= len(dense) < 400  # bisected to just enough
    assert len(adaptive_voxel_filter(line, 0.5, 200, 5.0)) == len(np.flatnonzero(line[:, 0] <= 5.0))
    problem, _ = make_problem()
    far = tfloc.get_matcher("cartographer-local", max_range=3.0)._points(problem)
    assert len(far) and np.hypot(far[:, 0], far[:, 1]).max() <= 3.0


def test_the_real_time_csm_searches_its_window_at_the_grid_resolution() -> None:
    problem, true = make_problem()
    grid = probability_grid(problem.map, 0.9)
    pts = tfloc.get_matcher("cartographer-local")._points(problem)
    pred = true.compose(Pose(0.1, -0.05, math.radians(4.0)))
    best, score, n = _csm.match(grid, pts, pred, 0.1, math.radians(20.0), 0.1, 0.1)
    step = _csm.angular_step(pts, 0.05)
    assert n == (2 * math.ceil(math.radians(20.0) / step) + 1) * 25  # ±2 cells in x and y
    assert 0.0 < score <= 0.9
    assert abs(best.x - pred.x) <= 0.1 + 1e-9 and abs(best.y - pred.y) <= 0.1 + 1e-9
    dist, orient = errors(best, true)
    assert dist < 0.05 and orient < 0.5  # the cell and the heading step of the truth
    _, zero, _ = _csm.match(grid, pts, TRUE_POSE, 0.0, 0.0, 0.1, 0.1)
    assert zero == pytest.approx(np.mean(grid.probability_at_cells(*grid.cells(TRUE_POSE.transform(pts)))))


def test_an_empty_scan_is_declined_and_the_prediction_kept() -> None:
    problem, _ = make_problem()
    m = tfloc.get_matcher("cartographer-local", max_range=0.0)
    est = m.localize(problem)
    assert est.declined and est.pose == problem.initial
    assert m.score(problem, problem.initial) == pytest.approx(0.5 * (1.0 - MIN_PROBABILITY) ** 2)


def test_a_grid_map_is_read_cell_for_cell() -> None:
    from tfloc.maps.grid import GridMap

    occ = np.zeros((20, 30), dtype=np.float32)
    occ[5, 7] = 1.0
    grid = probability_grid(GridMap(occ, 0.05, (1.0, 2.0)), 0.9)
    assert grid.prob.shape == (20, 30) and grid.origin == (1.0, 2.0)
    assert grid.prob[5, 7] == 0.9 and grid.prob[0, 0] == MIN_PROBABILITY
