"""The virtual sensor against analytic distances, shapely, and the map queries."""

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, box

from tfloc import LaserSpec, Pose, VectorMap


def analytic_box_ranges(pose: Pose, laser: LaserSpec, w: float, h: float) -> np.ndarray:
    a = pose.theta + laser.angles
    c, s = np.cos(a), np.sin(a)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(c > 1e-12, (w - pose.x) / c, np.where(c < -1e-12, -pose.x / c, np.inf))
        ty = np.where(s > 1e-12, (h - pose.y) / s, np.where(s < -1e-12, -pose.y / s, np.inf))
    r = np.minimum(tx, ty)
    return np.where(r < laser.max_range, r, np.inf)


@pytest.mark.parametrize("pose", [Pose(1, 1, 0), Pose(2.5, 0.7, 2.0), Pose(0.2, 2.8, -2.9)])
def test_square_room_matches_analytic(pose, lms200):
    room = VectorMap(outline=box(0, 0, 4, 3))
    assert np.allclose(room.raycast(pose, lms200), analytic_box_ranges(pose, lms200, 4, 3), atol=1e-9)


def test_no_hit_beyond_max_range_is_inf():
    room = VectorMap(outline=box(0, 0, 40, 30))
    r = room.raycast(Pose(20, 15, 0), LaserSpec.lms200())
    assert np.isinf(r).all()


def test_batch_equals_single_and_matches_shapely(test_room, lms200):
    rng = np.random.default_rng(3)
    poses = []
    while len(poses) < 20:
        xy = rng.uniform([0, 0], [10, 8])
        if test_room.is_free(xy[None])[0]:
            poses.append([*xy, rng.uniform(-np.pi, np.pi)])
    poses = np.array(poses)
    batch = test_room.raycast(poses, lms200)
    assert batch.shape == (20, lms200.n_beams)
    for p, row in zip(poses, batch, strict=True):
        assert np.array_equal(test_room.raycast(Pose(*p), lms200), row)
    # oracle: shapely intersection of each beam with all geometry
    walls = shapely.MultiLineString([s.reshape(2, 2) for s in test_room.segments])
    p = poses[0]
    for i in range(0, lms200.n_beams, 10):
        a = p[2] + lms200.angles[i]
        beam = LineString([p[:2], p[:2] + lms200.max_range * np.array([math.cos(a), math.sin(a)])])
        hit = beam.intersection(walls)
        want = np.inf if hit.is_empty else shapely.distance(shapely.points(p[:2]), hit)
        assert batch[0, i] == pytest.approx(want, abs=1e-9)


def test_is_free_in_bounds_and_sample_points(test_room):
    assert test_room.is_free(np.array([[3.0, 3.5]]))[0]
    assert not test_room.is_free(np.array([[2.0, 1.4]]))[0]          # inside the table
    assert not test_room.is_free(np.array([[9.0, 7.0]]))[0]          # in the notch, off the map
    assert not test_room.is_free(np.array([[0.05, 4.0]]), clearance=0.1)[0]
    assert test_room.in_bounds(np.array([[0.0, 4.0]]))[0] and not test_room.in_bounds(np.array([[-1, 4]]))[0]
    pts, normals = test_room.sample_points(0.1)
    assert pts.shape == normals.shape and len(pts) > 300
    assert np.allclose(np.hypot(*normals.T), 1.0)
    # every sample lies on a segment
    lines = shapely.MultiLineString([s.reshape(2, 2) for s in test_room.segments])
    assert shapely.distance(lines, shapely.points(pts)).max() < 1e-9
