"""Compiled turning function and matching against copies of the previous numpy versions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tfloc.paper.turning import TWO_PI, Match, TurningFunction, match, turning_function


# --- oracles: the implementations before the numba rewrite, verbatim -------------------------
def turning_function_ref(vertices):
    v = np.asarray(vertices, dtype=float)
    e = np.roll(v, -1, axis=0) - v
    length = np.hypot(e[:, 0], e[:, 1])
    e, length = e[length > 1e-12], length[length > 1e-12]
    if len(e) < 3:
        raise ValueError("a turning function needs a polygon with at least 3 edges")
    prev = np.roll(e, 1, axis=0)
    turn = np.arctan2(prev[:, 0] * e[:, 1] - prev[:, 1] * e[:, 0], np.einsum("ij,ij->i", prev, e))
    turn[0] = np.arctan2(e[0, 1], e[0, 0])
    breaks = np.concatenate(([0.0], np.cumsum(length))) / length.sum()
    breaks[-1] = 1.0
    return TurningFunction(breaks, np.cumsum(turn))


def match_ref(real, virtual):
    n_v = virtual.n_edges
    starts = virtual.breaks[:n_v]
    moved = (virtual.breaks[None, :n_v] - starts[:, None]) % 1.0
    grid = np.sort(np.concatenate((np.broadcast_to(real.breaks, (n_v, len(real.breaks))), moved),
                                  axis=1), axis=1)
    width = np.diff(grid, axis=1)
    mid = 0.5 * (grid[:, 1:] + grid[:, :-1])
    u = mid + starts[:, None]
    wrapped = u >= 1.0
    d = real(mid) - (virtual(np.where(wrapped, u - 1.0, u)) + TWO_PI * wrapped)
    rot = np.einsum("ij,ij->i", width, d)
    err2 = np.einsum("ij,ij->i", width, d * d) - rot * rot
    k = int(np.argmin(err2))
    rotation = (float(rot[k]) + np.pi) % TWO_PI - np.pi
    return Match(float(np.sqrt(max(err2[k], 0.0))), rotation, k), err2
# ------------------------------------------------------------------------------------------------


def _polygon(rng, n):
    """A random star-shaped polygon (counter-clockwise) with n vertices, sometimes with repeats."""
    phi = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = rng.uniform(0.2, 8.0, n)
    v = np.column_stack((r * np.cos(phi), r * np.sin(phi)))
    if rng.random() < 0.3:                                    # a zero-length edge
        i = int(rng.integers(0, n))
        v = np.insert(v, i, v[i], axis=0)
    if rng.random() < 0.3:                                    # closed through the origin
        v = np.vstack((np.zeros((1, 2)), v))
    return v


def _same_tf(a, b):
    np.testing.assert_allclose(a.breaks, b.breaks, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a.angles, b.angles, rtol=0, atol=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_turning_function_matches_oracle(seed):
    rng = np.random.default_rng(seed)
    for _ in range(150):
        v = _polygon(rng, int(rng.integers(3, 200)))
        _same_tf(turning_function(v), turning_function_ref(v))
        _same_tf(turning_function(v[::-1]), turning_function_ref(v[::-1]))


def test_turning_function_rejects_degenerate_polygons():
    for v in (np.zeros((0, 2)), np.zeros((3, 2)), np.array([[0, 0], [1, 0], [1, 0], [0, 0]])):
        with pytest.raises(ValueError):
            turning_function_ref(v)
        with pytest.raises(ValueError):
            turning_function(v)


@pytest.mark.parametrize("seed", range(4))
def test_match_matches_oracle(seed):
    rng = np.random.default_rng(100 + seed)
    for _ in range(150):
        n_r, n_v = (int(x) for x in rng.integers(3, 40, 2))
        real = turning_function(_polygon(rng, n_r))
        virtual = turning_function(_polygon(rng, n_v))
        got = match(real, virtual)
        ref, err2 = match_ref(real, virtual)
        if got.shift != ref.shift:   # a tie: only acceptable if both shifts are equally good
            assert abs(err2[got.shift] - err2[ref.shift]) <= 1e-12
            continue
        assert got.distance == pytest.approx(ref.distance, abs=1e-12, rel=0)
        assert got.rotation == pytest.approx(ref.rotation, abs=1e-12, rel=0)


def test_match_of_a_rotated_copy_is_near_zero():
    """Same polygon, rotated and re-started at another vertex: Err ≈ 0, rotation recovered."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        v = _polygon(rng, int(rng.integers(4, 30)))
        a = rng.uniform(-3.0, 3.0)
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        w = np.roll(v @ rot.T, int(rng.integers(0, len(v))), axis=0)
        real, virtual = turning_function(w), turning_function(v)
        got, (ref, _) = match(real, virtual), match_ref(real, virtual)
        assert got.distance < 1e-6 and ref.distance < 1e-6
        assert abs((got.rotation - a + np.pi) % TWO_PI - np.pi) < 1e-6
        assert abs((got.rotation - ref.rotation + np.pi) % TWO_PI - np.pi) < 1e-9


def test_match_of_scan_polygons_matches_oracle():
    """Polygons as the tf matcher builds them: ShortStraw corners closed through the origin."""
    from tfloc.core.laser import LaserSpec
    from tfloc.core.pose import Pose
    from tfloc.maps.vector import VectorMap
    from tfloc.paper.shape import ShapeConfig, scan_corners, scan_polygon

    rng = np.random.default_rng(11)
    laser = LaserSpec.lms200()
    segs = np.vstack((rng.uniform(-7, 7, (25, 4)),
                      [[-8, -8, 8, -8], [8, -8, 8, 8], [8, 8, -8, 8], [-8, 8, -8, -8]]))
    m = VectorMap.from_segments(segs)
    cfg = ShapeConfig(spacing=0.25)
    polys = [scan_polygon(scan_corners(m.raycast(Pose(*rng.uniform(-4, 4, 2), rng.uniform(-3, 3)),
                                                 laser), laser, cfg), cfg) for _ in range(12)]
    for p in polys:
        _same_tf(turning_function(p), turning_function_ref(p))
    for p, q in zip(polys[:-1], polys[1:], strict=True):
        real, virtual = turning_function(p), turning_function(q)
        got, (ref, _) = match(real, virtual), match_ref(real, virtual)
        assert (got.shift, got.distance, got.rotation) == pytest.approx(
            (ref.shift, ref.distance, ref.rotation), abs=1e-12, rel=0)


def test_mod1_is_python_modulo():
    from tfloc.paper.turning import _mod1

    xs = np.concatenate((np.random.default_rng(0).uniform(-3, 3, 20000),
                         [0.0, -0.0, 1.0, -1.0, 1 - 1e-17, -1e-300, 5e-324, -5e-324,
                          np.nextafter(-1, 0), np.nextafter(1, 0), 2.0, -2.5]))
    for x in xs:
        got, want = _mod1(float(x)), float(x) % 1.0
        assert got == want and math.copysign(1, got) == math.copysign(1, want), x
