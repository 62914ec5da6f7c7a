"""GridMap's virtual sensor against a VectorMap rasterised from the same geometry, and the rest of the
Map protocol (is_free, in_bounds, sample_points, bounds)."""

from __future__ import annotations

import numpy as np
import pytest
from _paths import MAPS

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.maps import GridMap, Map
from tfloc.maps.build import grid_from_scans, rasterize

ROOM = MAPS / "test-room.geojson"


@pytest.fixture(scope="module")
def room():
    from tfloc.io.geojson import read_vector_map

    return read_vector_map(ROOM)


def _free_poses(vmap, n: int, seed: int, clearance: float = 0.2) -> np.ndarray:
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = vmap.bounds
    xy = rng.uniform((xmin, ymin), (xmax, ymax), size=(20 * n, 2))
    xy = xy[vmap.is_free(xy, clearance)][:n]
    return np.column_stack((xy, rng.uniform(-np.pi, np.pi, len(xy))))


def _cos_incidence(vmap, poses: np.ndarray, ranges: np.ndarray, laser: LaserSpec) -> np.ndarray:
    """|cos| of the angle between each beam and the normal of the segment it hits."""
    s = vmap.segments
    a, e = s[:, :2], s[:, 2:] - s[:, :2]
    ang = poses[:, 2:3] + laser.angles[None, :]
    r = np.where(np.isfinite(ranges), ranges, 0.0)
    h = np.stack((poses[:, 0:1] + r * np.cos(ang), poses[:, 1:2] + r * np.sin(ang)), -1).reshape(-1, 2)
    u = np.clip(((h[:, None] - a[None]) * e[None]).sum(-1) / (e * e).sum(-1)[None], 0, 1)
    k = np.argmin(np.hypot(*(a[None] + u[..., None] * e[None] - h[:, None]).transpose(2, 0, 1)), axis=1)
    t = e[k] / np.hypot(*e[k].T)[:, None]
    beam = np.stack((np.cos(ang), np.sin(ang)), -1).reshape(-1, 2)
    return np.abs(beam[:, 0] * -t[:, 1] + beam[:, 1] * t[:, 0]).reshape(ranges.shape)


@pytest.mark.parametrize("res", [0.02, 0.05])
def test_raycast_agrees_with_vector_map_within_a_cell(room, res: float) -> None:
    laser = LaserSpec.lms200()
    grid = rasterize(room, res)
    poses = _free_poses(room, 150, seed=7)
    rv, rg = room.raycast(poses, laser), grid.raycast(poses, laser)
    assert (np.isfinite(rv) == np.isfinite(rg)).mean() > 0.995
    # Beams whose vector range is stable when the pose moves 1.5 cells: not grazing a corner or
    # an edge, so a cell-sized map must see the same wall.
    stable = np.isfinite(rv)
    for d in ((1.5 * res, 0, 0), (-1.5 * res, 0, 0), (0, 1.5 * res, 0), (0, -1.5 * res, 0)):
        rs = room.raycast(poses + d, laser)
        with np.errstate(invalid="ignore"):
            stable &= np.isfinite(rs) & (np.abs(rs - rv) <= 3 * res)
    assert stable.mean() > 0.75
    with np.errstate(invalid="ignore"):
        err = np.abs(rg - rv)[stable]
    cos_inc = _cos_incidence(room, poses, rv, laser)[stable]
    # within one cell measured along the wall normal, i.e. res / cos(incidence) along the beam
    assert (err * cos_inc <= res).mean() >= 0.995, np.percentile(err * cos_inc / res, [99, 99.9])
    # and unbiased: the hit is the middle of the beam's chord through the wall cell
    assert np.median(err) <= res / 4
    assert np.median(rg[stable] - rv[stable]) == pytest.approx(0.0, abs=res / 10)


def test_single_pose_equals_batch_and_inf_outside(room) -> None:
    laser = LaserSpec.lms200()
    grid = rasterize(room, 0.05)
    poses = _free_poses(room, 5, seed=3)
    batch = grid.raycast(poses, laser)
    for k, p in enumerate(poses):
        np.testing.assert_array_equal(grid.raycast(Pose(*p), laser), batch[k])
    # a pose outside the grid looking away sees nothing; looking back it sees the room
    away = grid.raycast(Pose(-5.0, 4.0, np.pi), laser)
    assert np.isinf(away).all()
    back = grid.raycast(Pose(-5.0, 4.0, 0.0), laser)
    assert np.isfinite(back[90]) and back[90] == pytest.approx(5.0, abs=0.05)


def test_short_max_range_gives_inf(room) -> None:
    grid = rasterize(room, 0.05)
    laser = LaserSpec.from_degrees(0.5, 180, 1)
    r = grid.raycast(_free_poses(room, 20, seed=5, clearance=0.6), laser)
    assert np.isinf(r).all()


def test_map_protocol_free_bounds_and_points(room) -> None:
    grid = rasterize(room, 0.05)
    assert isinstance(grid, Map)
    xmin, ymin, xmax, ymax = grid.bounds
    assert xmin <= 0 and ymin <= 0 and xmax >= 10 and ymax >= 8
    rng = np.random.default_rng(11)
    xy = rng.uniform((-1, -1), (11, 9), size=(4000, 2))
    assert (grid.in_bounds(xy) == ((xy[:, 0] >= xmin) & (xy[:, 0] < xmax) & (xy[:, 1] >= ymin)
                                   & (xy[:, 1] < ymax))).all()
    # away from walls (> 2 cells) the grid's free space is the vector map's; never inside walls
    gf = grid.is_free(xy)
    assert gf[room.is_free(xy, 0.1)].all()
    assert not gf[~room.is_free(xy, 0.0)].any()
    # clearance is honoured
    dist_ok = grid.is_free(xy, 0.3)
    assert room.is_free(xy[dist_ok], 0.2).all()
    pts, normals = grid.sample_points(0.1)
    assert pts.shape == normals.shape and len(pts) > 300
    np.testing.assert_allclose(np.hypot(*normals.T), 1.0, atol=1e-9)
    # every point lies on a wall (within a cell), and its normal is perpendicular to that wall
    s = room.segments
    a, e = s[:, :2], s[:, 2:] - s[:, :2]
    u = np.clip(((pts[:, None] - a[None]) * e[None]).sum(-1) / (e * e).sum(-1)[None], 0, 1)
    d = np.hypot(*(a[None] + u[..., None] * e[None] - pts[:, None]).transpose(2, 0, 1))
    k = d.argmin(axis=1)
    assert d.min(axis=1).max() <= 0.05
    t = e[k] / np.hypot(*e[k].T)[:, None]
    assert np.median(np.abs((normals * t).sum(1))) < 0.1


def test_grid_from_scans_reproduces_the_room(room) -> None:
    """Scans simulated in the vector map, placed at their poses, give a grid whose virtual sensor
    matches the scans."""
    laser = LaserSpec.lms200()
    poses = _free_poses(room, 60, seed=21, clearance=0.3)
    scans = room.raycast(poses, laser)
    grid = grid_from_scans(scans, poses, laser, resolution=0.05)
    assert isinstance(grid, GridMap) and grid.occupied.sum() > 200
    test = _free_poses(room, 20, seed=22, clearance=0.3)
    rv, rg = room.raycast(test, laser), grid.raycast(test, laser)
    both = np.isfinite(rv) & np.isfinite(rg)
    assert both.mean() > 0.9
    assert np.median(np.abs(rv - rg)[both]) < 0.03
    assert grid.is_free(poses[:, :2]).mean() > 0.95  # carved


def test_in_bounds_is_the_cells_of_cell_of_inside_the_grid():
    """The compiled test against the numpy rule it replaced (``cell_of``'s cells within the grid),
    on random points and on every cell edge, with an origin and a resolution that round."""
    grid = GridMap(np.zeros((37, 53)), 0.05, origin=(-1.234567, 0.1))
    rng = np.random.default_rng(2)
    xmin, ymin, xmax, ymax = grid.bounds
    edges_x = grid.origin[0] + grid.resolution * np.arange(-1, 55)
    edges_y = grid.origin[1] + grid.resolution * np.arange(-1, 39)
    xy = np.concatenate((rng.uniform((xmin - 1, ymin - 1), (xmax + 1, ymax + 1), (20000, 2)),
                         np.column_stack((edges_x, np.full(edges_x.size, 0.5))),
                         np.column_stack((np.full(edges_y.size, 0.1), edges_y)),
                         np.nextafter(np.column_stack((edges_x[:38], edges_y[:38])), -np.inf),
                         [[np.nan, 0.5], [0.1, np.inf], [-np.inf, 0.5], [1e300, 0.5], [-1e300, 0.5]]))
    with np.errstate(invalid="ignore"):
        i, j = grid.cell_of(xy)
    W, H = grid.shape[1], grid.shape[0]
    want = (i >= 0) & (i < W) & (j >= 0) & (j < H) & np.isfinite(xy).all(axis=1)
    got = grid.in_bounds(xy)
    assert got.dtype == bool and got.shape == (len(xy),) and np.array_equal(got, want)
    assert got.sum() > 1000 and grid.in_bounds(np.array([0.0, 0.5])).tolist() == [True]
