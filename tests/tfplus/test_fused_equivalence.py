"""The compiled paths of ``tf-plus`` and ``tf`` added for speed give the same answers, bit for
bit, as the step-by-step code they replace (the faster path is switched off to compare)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _tf_cases import TRUE, noisy_scan
from _tfplus_oracles import step_by_step_tfplus
from numba import njit

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.tfplus.refine import RefineConfig, _virtual_geometry, refine
from tfloc.tfplus.virtual_kernel import virtual_geometry_kernel

ROOT = Path(__file__).resolve().parents[2]


def _poses(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` poses up to 0.4 m / 6° from the test pose."""
    return np.column_stack((TRUE.x + rng.uniform(-0.4, 0.4, n), TRUE.y + rng.uniform(-0.4, 0.4, n),
                            TRUE.theta + rng.uniform(-0.1, 0.1, n)))


def test_virtual_geometry_kernel_matches_numpy() -> None:
    laser = LaserSpec.lms200()
    rng = np.random.default_rng(3)
    ranges = rng.uniform(0.5, 12.0, (5, laser.n_beams))
    ranges[:, ::17] = np.inf                      # no returns, and runs of repeated points
    ranges[1, 40:44] = ranges[1, 39]
    ranges[2, 60:62] = 0.0
    ranges[3] = ranges[3, 0]
    q, n = _virtual_geometry(ranges, laser)
    with np.errstate(invalid="ignore", divide="ignore"):
        kq, kn = virtual_geometry_kernel(ranges, np.cos(laser.angles), np.sin(laser.angles),
                                         float(laser.max_range))
    np.testing.assert_array_equal(kq, q)
    np.testing.assert_array_equal(kn, n)


def test_tangent_rule_from_squares_equals_the_rule_from_hypot() -> None:
    """The tangent choice of the virtual geometry, decided from squared step lengths where they
    are clearly apart, equals the choice from ``hypot`` everywhere: also at steps exactly 3:1
    apart, exactly equal, a ulp apart, zero or missing (NaN)."""
    from tfloc.tfplus.virtual_kernel import _sides

    def by_hypot(f, b):
        lf, lb = float(np.hypot(*f)), float(np.hypot(*b))     # libm's, as numba's and numpy's
        lf, lb = (math.inf if math.isnan(x) else x for x in (lf, lb))
        return 0 if (lf < 3 * lb and lb < 3 * lf) else (-1 if lf <= lb else 1)

    rng = np.random.default_rng(14)
    cases = [((3.0, 0.0), (1.0, 0.0)), ((1.0, 0.0), (3.0, 0.0)), ((0.0, 2.0), (2.0, 0.0)),
             ((0.6, 0.8), (1.0, 0.0)), ((3.0, 4.0), (0.0, 5.0)), ((0.0, 0.0), (1.0, 0.0)),
             ((0.0, 0.0), (0.0, 0.0)), ((np.nan, np.nan), (1.0, 0.0)),
             ((1.0, 0.0), (np.nan, np.nan)), ((np.nan, np.nan), (np.nan, np.nan)),
             ((math.nextafter(3.0, 4.0), 0.0), (1.0, 0.0)), ((math.nextafter(3.0, 2.0), 0.0), (1.0, 0.0))]
    for _ in range(2000):
        f = rng.normal(0, 1, 2)
        k = rng.choice([1.0, 3.0, 1 / 3, rng.uniform(0.1, 10)])
        angle = rng.uniform(-math.pi, math.pi)
        b = np.hypot(*f) * k * np.array([math.cos(angle), math.sin(angle)])
        cases.append((tuple(f), tuple(b)))
    for f, b in cases:
        assert _sides(f[0], f[1], b[0], b[1]) == by_hypot(f, b), (f, b)


@pytest.mark.parametrize("config", [RefineConfig(), RefineConfig(prune_after=0),
                                    RefineConfig(iterations=3, prune_after=3, keep=1),
                                    RefineConfig(iterations=4, inner=1, prune_after=9)])
def test_fused_vector_refinement_is_bit_identical(config: RefineConfig, test_room, lms200,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(5)
    for seed in range(6):
        points = lms200.to_points(noisy_scan(test_room, lms200, TRUE, seed))
        poses = _poses(rng, 4)
        fused = refine(test_room, lms200, points, poses, config)
        with monkeypatch.context() as mp:
            step_by_step_tfplus(mp)
            loop = refine(test_room, lms200, points, poses, config)
        assert fused.shape == loop.shape and fused.tobytes() == loop.tobytes()


def test_grid_scores_kernel_equals_the_plain_sum(test_room, lms200) -> None:
    from tfloc.maps.fields import distance_field
    from tfloc.tfplus.coarse_kernel import grid_scores_kernel

    f = distance_field(test_room, 0.05, 0.3)
    points = np.ascontiguousarray(lms200.to_points(noisy_scan(test_room, lms200, TRUE))[::9])
    rng = np.random.default_rng(2)
    positions = rng.uniform(-1.0, 9.0, (300, 2))      # some outside the table: clipped
    headings = rng.uniform(-math.pi, math.pi, 7)
    table, (ox, oy) = f.distance, f.corner
    ny, nx = table.shape
    expect = np.zeros((len(positions), len(headings)))
    for i in range(len(points)):                     # the sum over the points, in order
        c, s = np.cos(headings), np.sin(headings)
        qx = (c * points[i, 0] - s * points[i, 1]) - ox
        qy = (s * points[i, 0] + c * points[i, 1]) - oy
        ix = np.clip(np.floor((positions[:, :1] + qx) * (1.0 / f.resolution)), 0, nx - 1)
        iy = np.clip(np.floor((positions[:, 1:] + qy) * (1.0 / f.resolution)), 0, ny - 1)
        expect += table[iy.astype(int), ix.astype(int)]
    got = grid_scores_kernel(table, float(ox), float(oy), f.resolution, points, positions, headings)
    assert got.tobytes() == (expect / len(points)).tobytes()


def test_grid_scores_on_a_lattice_equal_the_plain_sum(test_room, lms200) -> None:
    """The lattice path (one cell index per heading and point) gives the plain loop's scores,
    also where the pattern leaves the table (clipped) and on a lattice that is no whole number
    of cells (the plain path)."""
    from tfloc.maps.fields import distance_field
    from tfloc.tfplus.coarse import _offsets
    from tfloc.tfplus.coarse_kernel import grid_scores_kernel

    f = distance_field(test_room, 0.05, 0.3)
    table, (ox, oy) = f.distance, f.corner
    rng = np.random.default_rng(13)
    points = np.ascontiguousarray(lms200.to_points(noisy_scan(test_room, lms200, TRUE)))
    headings = rng.uniform(-math.pi, math.pi, 9)
    for centre in rng.uniform(-2.0, 9.0, (12, 2)):
        for step in (0.2, 0.15, 0.07):
            positions = centre + _offsets(3.3, step)
            positions = np.ascontiguousarray(positions[rng.random(len(positions)) < 0.7])
            plain = grid_scores_kernel(table, float(ox), float(oy), f.resolution, points,
                                       positions, headings)
            fast = grid_scores_kernel(table, float(ox), float(oy), f.resolution, points,
                                      positions, headings, step)
            assert fast.tobytes() == plain.tobytes()


@njit(cache=False)
def _pairs_reference(points, delta, q, normal, angle_min, resolution, window, gate):
    """The point-to-line pairing as it was written before the speed work (exact atan2, NaN tests
    in the window, the Jacobian as a tuple)."""
    k_n, m = delta.shape[0], points.shape[0]
    n = q.shape[1]
    hh = np.zeros((k_n, 3, 3))
    gg = np.zeros((k_n, 3))
    res = np.full((k_n, m), np.nan)
    for k in range(k_n):
        c, s = math.cos(delta[k, 2]), math.sin(delta[k, 2])
        for i in range(m):
            rx = c * points[i, 0] - s * points[i, 1]
            ry = s * points[i, 0] + c * points[i, 1]
            x, y = rx + delta[k, 0], ry + delta[k, 1]
            j0 = int(round((math.atan2(y, x) - angle_min) / resolution))
            best, bj = gate * gate, -1
            for j in range(max(j0 - window, 0), min(j0 + window + 1, n)):
                qx = q[k, j, 0]
                if math.isnan(qx) or math.isnan(normal[k, j, 0]):
                    continue
                d2 = (x - qx) ** 2 + (y - q[k, j, 1]) ** 2
                if d2 < best:
                    best, bj = d2, j
            if bj < 0:
                continue
            nx, ny = normal[k, bj, 0], normal[k, bj, 1]
            r = nx * (x - q[k, bj, 0]) + ny * (y - q[k, bj, 1])
            res[k, i] = r
            jac = (nx, ny, -nx * ry + ny * rx)
            for a in range(3):
                gg[k, a] += jac[a] * r
                for b in range(3):
                    hh[k, a, b] += jac[a] * jac[b]
    return hh, gg, res


def test_pairs_kernel_equals_the_reference(test_room, lms200) -> None:
    from tfloc.tfplus.virtual_kernel import pairs_kernel

    rng = np.random.default_rng(11)
    points = lms200.to_points(noisy_scan(test_room, lms200, TRUE, 3))
    # points on every bearing, including exact half steps between beams
    half = lms200.angle_min + (np.arange(lms200.n_beams - 1) + 0.5) * lms200.resolution
    points = np.vstack((points, 2.0 * np.column_stack((np.cos(half), np.sin(half)))))
    for gate in (0.05, 0.5):
        poses = _poses(rng, 4)
        q, normal = _virtual_geometry(test_room.raycast(poses, lms200), lms200)
        delta = rng.normal(0.0, 0.02, (4, 3)) if gate > 0.1 else np.zeros((4, 3))
        got = pairs_kernel(points, delta, q, normal, lms200.angle_min, lms200.resolution, 6, gate,
                           np.cos(lms200.angles), np.sin(lms200.angles))
        ref = _pairs_reference(points, delta, q, normal, lms200.angle_min, lms200.resolution, 6,
                               gate)
        for a, b in zip(got, ref, strict=True):
            assert a.tobytes() == b.tobytes()


def _fft_rotations(real, virtual, skip: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The histograms' correlation by FFTs, step by step: the window's shifts, its values and the
    order of its local maxima (highest first)."""
    from tfloc.tfplus.headings import edge_histogram

    hr = edge_histogram(real, 720, math.radians(1.0), skip)
    hv = edge_histogram(virtual, 720, math.radians(1.0), skip)
    corr = np.real(np.fft.ifft(np.fft.fft(hr) * np.conj(np.fft.fft(hv))))
    k = int(np.floor(math.radians(20) / (2 * np.pi / 720)))
    c = corr[np.arange(-k, k + 1) % 720]
    peak = (c >= np.roll(c, 1)) & (c >= np.roll(c, -1))
    peak[0] = peak[-1] = False
    order = np.argsort(-np.where(peak, c, -np.inf))
    return np.arange(-k, k + 1), c, order[peak[order]]


def _rotation_cases(test_room, lms200):
    from tfloc.paper.shape import ShapeConfig, scan_turning_function

    shape = ShapeConfig(spacing=0.05)
    rng = np.random.default_rng(4)
    real = scan_turning_function(noisy_scan(test_room, lms200, TRUE, 1), lms200, shape)
    for pose in _poses(rng, 12):
        virtual = scan_turning_function(test_room.raycast(pose, lms200), lms200, shape)
        for skip in (True, False):
            yield real, virtual, skip
    # a bare box: its walls' directions correlate in one peak within ±20°
    from shapely.geometry import box

    from tfloc.maps.vector import VectorMap

    room = VectorMap(outline=box(0, 0, 6, 4))
    for d_theta in (0.0, 0.05, -0.12):
        real = scan_turning_function(noisy_scan(room, lms200, Pose(2.5, 1.5, 0.3)), lms200, shape)
        virtual = scan_turning_function(room.raycast(Pose(2.6, 1.4, 0.3 + d_theta), lms200),
                                        lms200, shape)
        yield real, virtual, True


def test_fft_rotation_candidates_equal_the_step_by_step_histograms(test_room, lms200) -> None:
    from _tfplus_oracles import rotation_candidates_fft

    for real, virtual, skip in _rotation_cases(test_room, lms200):
        shifts, c, order = _fft_rotations(real, virtual, skip)
        order = order[:3] if len(order) else np.array([int(np.argmax(c))])
        expect = shifts[order] * (2 * np.pi / 720)
        got = rotation_candidates_fft(real, virtual, math.radians(20), 3, skip_closure=skip)
        assert got.tobytes() == expect.tobytes()


def test_rotation_candidates_are_the_fft_peaks_above_rounding_noise(test_room, lms200) -> None:
    """The direct correlation gives the FFT's real peaks, in its order, and drops the local
    maxima of its rounding noise; the values agree to rounding."""
    from _tfplus_oracles import rotation_candidates

    from tfloc.tfplus.headings import _NOISE, _correlation, _pair_kernel, _raw_histograms

    fewer = 0
    for real, virtual, skip in _rotation_cases(test_room, lms200):
        shifts, c, order = _fft_rotations(real, virtual, skip)
        raw = _raw_histograms(real.breaks, real.angles, virtual.breaks, virtual.angles, 720, skip)
        direct = _correlation(raw, _pair_kernel(720, math.radians(1.0)), len(shifts) // 2)
        np.testing.assert_allclose(direct, c, rtol=0, atol=1e-12 * np.abs(c).max())
        real_peaks = order[c[order] > _NOISE * c.max()][:3]
        expect = shifts[real_peaks if len(real_peaks) else [int(np.argmax(c))]] * (2 * np.pi / 720)
        got = rotation_candidates(real, virtual, math.radians(20), 3, skip_closure=skip)
        assert got.tobytes() == expect.tobytes()
        fewer += len(real_peaks) < min(3, len(order))
    assert fewer > 0          # the noise rule was exercised


def test_smallest_kernel_orders_by_score_then_index() -> None:
    from tfloc.tfplus.coarse_kernel import smallest_kernel

    rng = np.random.default_rng(8)
    for n in (0, 1, 7, 64, 65, 500, 3000):
        for _ in range(5):
            scores = rng.integers(0, 25, n) / 7.0          # many ties
            got = smallest_kernel(scores, 64)
            assert np.array_equal(got, np.lexsort((np.arange(n), scores))[:64])


def test_coarse_candidates_are_the_shortlist_rescored_and_thinned(test_room, lms200) -> None:
    from _tfplus_oracles import grid_scores

    from tfloc.tfplus.coarse import best_candidates, candidates, lattice, pose_scores
    from tfloc.tfplus.view import map_view

    field = map_view(test_room, 0.05, 0.3, 0.3)
    pooled = map_view(test_room, 0.05, 0.3, 0.3, 0.1)
    points = lms200.to_points(noisy_scan(test_room, lms200, TRUE))
    positions = lattice(test_room, field, np.array([TRUE.x + 0.4, TRUE.y - 0.3]), 2.0, 0.2, 0.1)
    headings = TRUE.theta + np.radians(np.arange(-9, 10, 3.0))
    for shortlist, count in ((64, 4), (5, 3), (10_000, 2)):
        got, scores, rescored = candidates(pooled, points, positions, headings, 9, shortlist,
                                           count, 0.3)
        first = grid_scores(pooled, points[::9], positions, headings).ravel()
        top = np.lexsort((np.arange(first.size), first))[:shortlist]   # ties by index
        poses = np.column_stack((positions[top // len(headings)], headings[top % len(headings)]))
        expect = best_candidates(poses, pose_scores(pooled, points, poses), count, 0.3)
        assert rescored == len(top)
        assert got.tobytes() == expect.tobytes()
        assert scores.tobytes() == pose_scores(pooled, points, expect).tobytes()


def test_pairwise_sum_is_numpys_mean() -> None:
    from tfloc.tfplus.refine import truncated_cost
    from tfloc.tfplus.virtual_kernel import _pairwise_sum, truncated_cost_kernel

    rng = np.random.default_rng(9)
    for n in [*range(1, 140), 181, 255, 256, 361, 721, 1081, 4000]:
        x = rng.random(n) ** 3
        assert _pairwise_sum(x) / n == np.vstack((x, x)).mean(axis=1)[0]
    r = rng.normal(0, 0.1, (4, 361))
    r[:, ::13] = np.nan
    assert truncated_cost_kernel(r, 0.1).tobytes() == truncated_cost(np.abs(r), 0.1).tobytes()


@pytest.mark.parametrize("grid", [False, True])
def test_compiled_selection_cost_equals_the_numpy_steps(grid: bool, test_room, lms200) -> None:
    from _tf_cases import cost_cases

    from tfloc.tfplus.cost import scan_cost, scan_cost_steps

    rng = np.random.default_rng(10)
    for m, field, ranges in cost_cases(test_room, lms200, grid):
        poses = np.vstack((TRUE.as_array(), _poses(rng, 3)))
        got = scan_cost(m, lms200, ranges, poses, 6, 0.1, True, field)
        ref = scan_cost_steps(m, lms200, ranges, poses, 6, 0.1, True, field)
        assert got.tobytes() == ref.tobytes()


def test_tf_plus_scan_rotations_equal_the_step_by_step_ones(test_room, lms200) -> None:
    """The seeds' fused call (both turning functions, histograms, correlation, peaks) gives the
    rotations of the step-by-step turning functions, and None where a polygon is degenerate."""
    from _tfplus_oracles import rotation_candidates

    from tfloc.paper.shape import ShapeConfig, scan_turning_function
    from tfloc.tfplus.headings import scan_rotations

    rng = np.random.default_rng(6)
    for shape in (ShapeConfig(spacing=0.05), ShapeConfig(spacing=0.05, resampling="path"),
                  ShapeConfig(close_through_origin=False)):
        for seed, pose in enumerate(_poses(rng, 6)):
            ranges = noisy_scan(test_room, lms200, Pose(*pose), seed)
            ranges[::23] = np.inf
            virtual = test_room.raycast(TRUE, lms200)
            a, b = scan_turning_function(ranges, lms200, shape), scan_turning_function(virtual, lms200, shape)
            expect = rotation_candidates(a, b, math.radians(20), 3)
            got = scan_rotations(ranges, virtual, lms200, shape, math.radians(20), 3)
            assert got.tobytes() == expect.tobytes()
    few = np.full(lms200.n_beams, np.inf)
    few[90:92] = 2.0
    assert scan_turning_function(few, lms200) is None
    assert scan_rotations(few, test_room.raycast(TRUE, lms200), lms200, ShapeConfig(), 0.3, 3) is None


def test_lattice_on_a_vector_map_equals_the_map_queries() -> None:
    import shapely

    from tfloc.io.maps import load_map
    from tfloc.tfplus.coarse import _offsets, lattice
    from tfloc.tfplus.view import map_view

    m = load_map(ROOT / "data" / "maps" / "office-2.geojson")
    view = map_view(m, 0.05, 0.3, 0.3)
    assert m.area_rings(build=True) is not None and m.free_rings(build=True) is not None
    rng = np.random.default_rng(8)
    x0, y0, x1, y1 = m.bounds
    free, area = m._free_space(0.0), m.area
    for centre in rng.uniform((x0 - 1, y0 - 1), (x1 + 1, y1 + 1), (40, 2)):
        for clearance in (0.1, 0.07, 0.0):
            xy = centre[None, :] + _offsets(3.3, 0.2)
            keep = view(xy) >= clearance
            keep &= shapely.intersects_xy(area, xy[:, 0], xy[:, 1])
            keep &= shapely.contains_xy(free, xy[:, 0], xy[:, 1])
            got = lattice(m, view, centre, 3.3, 0.2, clearance)
            assert got.tobytes() == xy[keep].tobytes()


def test_lattice_on_a_grid_map_equals_the_map_queries() -> None:
    from tfloc.io.maps import load_map
    from tfloc.maps.build import rasterize
    from tfloc.tfplus.coarse import _offsets, lattice
    from tfloc.tfplus.view import map_view

    grid = rasterize(load_map(ROOT / "data" / "maps" / "office-2.geojson"), 0.05)
    view = map_view(grid, 0.05, 0.3, 0.3)
    rng = np.random.default_rng(12)
    x0, y0, x1, y1 = grid.bounds
    for centre in rng.uniform((x0 - 1, y0 - 1), (x1 + 1, y1 + 1), (40, 2)):
        for clearance in (0.1, 0.07, 0.0):
            xy = centre[None, :] + _offsets(3.3, 0.2)
            keep = view(xy) >= clearance
            keep &= grid.in_bounds(xy)
            keep &= grid.is_free(xy)
            got = lattice(grid, view, centre, 3.3, 0.2, clearance)
            assert got.tobytes() == xy[keep].tobytes()
