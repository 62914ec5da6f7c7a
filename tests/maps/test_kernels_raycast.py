"""The beam-interval raycast kernel against the brute-force oracle and an analytic room."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.maps._raycast import raycast_segments, raycast_segments_bruteforce
from tfloc.maps.segment_index import MIN_SEGMENTS, NO_INDEX, build_index
from tfloc.maps.vector import VectorMap

LASERS = [
    LaserSpec.lms200(),
    LaserSpec.from_degrees(30.0, 360.0, 1.0, -180.0),          # full circle, first = last beam
    LaserSpec.from_degrees(8.0, 359.0, 1.0, 0.0),              # wraps through the heading
    LaserSpec.from_degrees(5.6, 240.0, 0.36),                  # URG-like, 667 beams
    LaserSpec.from_degrees(10.0, 270.0, 0.25, -135.0),
]


def _same(fast: np.ndarray, brute: np.ndarray) -> None:
    assert fast.shape == brute.shape
    np.testing.assert_array_equal(np.isinf(fast), np.isinf(brute))
    np.testing.assert_allclose(fast, brute, rtol=0.0, atol=1e-9)


def _both(poses, laser, segs):
    poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 3))
    segs = np.ascontiguousarray(np.asarray(segs, dtype=float).reshape(-1, 4))
    a = np.asarray(laser.angles, dtype=float)
    return (raycast_segments(poses, a, segs, laser.max_range, NO_INDEX),
            raycast_segments_bruteforce(poses, a, segs, laser.max_range, NO_INDEX))


@pytest.mark.parametrize("laser", LASERS, ids=lambda s: f"{math.degrees(s.fov):.0f}deg")
@pytest.mark.parametrize("seed", range(8))
def test_random_maps_match_bruteforce(laser, seed):
    rng = np.random.default_rng(seed)
    n = rng.integers(1, 150)
    a = rng.uniform(-10, 10, (n, 2))
    length = rng.choice([0.05, 0.5, 3.0, 15.0], n) * rng.uniform(0.1, 1.0, n)
    phi = rng.uniform(-np.pi, np.pi, n)
    segs = np.column_stack((a, a + length[:, None] * np.column_stack((np.cos(phi), np.sin(phi)))))
    poses = np.column_stack((rng.uniform(-10, 10, (40, 2)), rng.uniform(-4, 4, 40)))
    fast, brute = _both(poses, laser, segs)
    assert np.isfinite(brute).any()
    _same(fast, brute)


@pytest.mark.parametrize("laser", LASERS[:3], ids=lambda s: f"{math.degrees(s.fov):.0f}deg")
def test_endpoints_on_beams_and_collinear_segments(laser):
    """Segment ends exactly on beam directions, segments along beams, poses on segments/ends."""
    rng = np.random.default_rng(3)
    pose = np.array([0.3, -0.2, 0.4])
    ang = pose[2] + laser.angles
    segs = []
    for i in range(0, laser.n_beams, 7):
        r1, r2 = rng.uniform(0.5, 9.0, 2)
        j = min(i + int(rng.integers(0, 4)), laser.n_beams - 1)
        p1 = pose[:2] + r1 * np.array([np.cos(ang[i]), np.sin(ang[i])])
        p2 = pose[:2] + r2 * np.array([np.cos(ang[j]), np.sin(ang[j])])
        segs.append(np.concatenate((p1, p2)))                     # ends on beams i and j
        p3 = pose[:2] + (r1 + 0.5) * np.array([np.cos(ang[i]), np.sin(ang[i])])
        segs.append(np.concatenate((p1, p3)))                     # collinear with beam i
    segs = np.array(segs)
    poses = [pose, np.r_[segs[0, :2], 0.1], np.r_[0.5 * (segs[2, :2] + segs[2, 2:]), -1.0],
             np.r_[segs[5, 2:], 2.0]]
    fast, brute = _both(poses, laser, segs)
    assert np.isfinite(brute).sum() > 20
    _same(fast, brute)


def test_axis_aligned_grid_of_walls_with_poses_on_grid_lines():
    """Many exact ties: walls on integer lines, poses and beam angles hitting corners exactly."""
    laser = LaserSpec.from_degrees(12.0, 360.0, 0.5, -180.0)
    segs = [[x, 0, x, 10] for x in range(0, 11, 2)] + [[0, y, 10, y] for y in range(0, 11, 2)]
    segs += [[1, 1, 3, 3], [3, 3, 5, 5], [5, 1, 7, 3]]            # diagonals through grid points
    poses = [[1, 1, 0.0], [2, 3, math.pi / 4], [5, 5, math.pi / 2], [4, 4, 0.0], [3, 1, -math.pi]]
    fast, brute = _both(poses, laser, segs)
    _same(fast, brute)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(*[st.integers(-8, 8)] * 4), min_size=1, max_size=30),
       st.tuples(st.integers(-8, 8), st.integers(-8, 8), st.integers(-8, 8)),
       st.sampled_from(LASERS[:3]))
def test_integer_maps_match_bruteforce(segs, pose, laser):
    """Integer coordinates give exact collinearities, endpoint hits and poses on segments."""
    segs = np.array(segs, dtype=float) / 2.0
    segs = segs[np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]) > 0]
    if len(segs) == 0:
        return
    p = np.array([pose[0] / 2.0, pose[1] / 2.0, pose[2] * math.pi / 8])
    fast, brute = _both(p, laser, segs)
    _same(fast, brute)


def test_square_room_is_analytic():
    laser = LaserSpec.from_degrees(20.0, 360.0, 1.0, -180.0)
    half = 2.5
    room = VectorMap.from_segments(np.array([[-half, -half, half, -half], [half, -half, half, half],
                                             [half, half, -half, half], [-half, half, -half, -half]]))
    for theta in (0.0, 0.3, -2.0):
        r = room.raycast(Pose(0.0, 0.0, theta), laser)
        phi = theta + laser.angles
        expected = half / np.maximum(np.abs(np.cos(phi)), np.abs(np.sin(phi)))
        np.testing.assert_allclose(r, expected, rtol=0.0, atol=1e-9)


def test_out_of_range_and_no_segments():
    laser = LaserSpec.lms200()
    fast, brute = _both([0, 0, 0], laser, [[20, -1, 20, 1]])
    assert np.isinf(fast).all() and np.isinf(brute).all()
    fast, brute = _both([0, 0, 0], laser, np.empty((0, 4)))
    assert np.isinf(fast).all() and fast.shape == (1, laser.n_beams)


def test_non_uniform_angles_fall_back_to_bruteforce():
    rng = np.random.default_rng(0)
    angles = np.sort(rng.uniform(-np.pi, np.pi, 50))
    angles.flags.writeable = False  # read-only, as LaserSpec.angles are (no second compilation)
    segs = np.ascontiguousarray(rng.uniform(-5, 5, (30, 4)))
    poses = np.ascontiguousarray(np.column_stack((rng.uniform(-5, 5, (5, 2)), np.zeros(5))))
    np.testing.assert_array_equal(raycast_segments(poses, angles, segs, 10.0, NO_INDEX),
                                  raycast_segments_bruteforce(poses, angles, segs, 10.0, NO_INDEX))


def test_fast_atan2_error_bound():
    """The arc computation's atan2 approximation stays far inside the kernel's angle margin."""
    from tfloc.maps._raycast import _ANGLE_MARGIN, _atan2

    rng = np.random.default_rng(0)
    pts = np.vstack((rng.normal(size=(20000, 2)) * 10.0 ** rng.uniform(-6, 3, (20000, 1)),
                     [[1, 0], [0, 1], [-1, 0], [0, -1], [1, 1], [-1, -1], [-1, 1e-300], [-1, -1e-300]]))
    err = [abs(math.remainder(_atan2(y, x) - math.atan2(y, x), 2 * math.pi)) for x, y in pts]
    assert max(err) < 1e-5 < _ANGLE_MARGIN / 5


@pytest.mark.parametrize("laser", LASERS, ids=lambda s: f"{math.degrees(s.fov):.0f}deg")
def test_poses_sharing_a_position_give_the_ranges_of_single_casts(laser):
    """Consecutive poses at one position (tf's seven orientations) reuse the heading-independent
    work; each row must equal the cast of its pose alone, bit for bit."""
    rng = np.random.default_rng(7)
    segs = np.ascontiguousarray(rng.uniform(-6, 6, (60, 4)))
    poses = []
    for _ in range(20):
        x, y, th = rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-4, 4)
        poses += [[x, y, th + k * math.radians(1.0)] for k in range(-3, 4)]
    poses = np.ascontiguousarray(poses)
    a = np.asarray(laser.angles, dtype=float)
    batch = raycast_segments(poses, a, segs, laser.max_range, NO_INDEX)
    single = np.vstack([raycast_segments(p[None], a, segs, laser.max_range, NO_INDEX) for p in poses])
    np.testing.assert_array_equal(batch, single)


@pytest.mark.parametrize("laser", LASERS[:3], ids=lambda s: f"{math.degrees(s.fov):.0f}deg")
def test_the_segment_index_gives_the_ranges_of_the_linear_test(laser):
    """With the map's segments bucketed, a cast tests only the cells within range: the same
    ranges, bit for bit, for poses inside, at the edge of and outside the indexed area, and the
    same through the brute force."""
    rng = np.random.default_rng(15)
    segs = np.ascontiguousarray(np.vstack((rng.uniform(-40, 40, (MIN_SEGMENTS, 2)),)).repeat(2, axis=1))
    segs[:, 2:] += rng.normal(0, 1.5, (MIN_SEGMENTS, 2))           # short walls all over
    segs = np.ascontiguousarray(np.vstack((segs, [[-45.0, -45.0, 45.0, 45.0]])))   # and a long one
    index = build_index(segs, laser.max_range)
    assert index[3] > 0 and build_index(segs[:MIN_SEGMENTS - 1], laser.max_range)[3] == 0
    poses = np.column_stack((rng.uniform(-60, 60, (300, 2)), rng.uniform(-4, 4, 300)))
    poses = np.ascontiguousarray(np.vstack((poses, np.repeat(poses[:5], 7, axis=0))))
    a = np.asarray(laser.angles, dtype=float)
    plain = raycast_segments(poses, a, segs, laser.max_range, NO_INDEX)
    np.testing.assert_array_equal(raycast_segments(poses, a, segs, laser.max_range, index), plain)
    np.testing.assert_array_equal(
        raycast_segments_bruteforce(poses[:40], a, segs, laser.max_range, index), plain[:40])
    assert np.isfinite(plain).mean() > 0.05                         # the walls are seen


def test_a_vector_map_builds_its_index_once_per_range():
    rng = np.random.default_rng(16)
    xy = rng.uniform(0, 50, (MIN_SEGMENTS + 10, 2))
    m = VectorMap.from_segments(np.hstack((xy, xy + rng.normal(0, 1, xy.shape))))
    assert m.segment_index(10.0) is m.segment_index(10.0)
    assert m.segment_index(30.0)[2] != m.segment_index(10.0)[2]
    small = VectorMap.from_segments(np.array([[0.0, 0.0, 1.0, 1.0]]))
    assert small.segment_index(10.0) is NO_INDEX
