"""`tf-plus` on grid maps whose walls are drawn several cells thick (as maps built from real scans
are): where the grid's ray and the see-through march end, the walls' surfaces, the coarse bound,
and that the refinement and the whole matcher stay unbiased where the virtual scan does not."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.ndimage import binary_dilation
from shapely.geometry import box

import tfloc
from tfloc import GridMap, LaserSpec, Pose, Problem, VectorMap
from tfloc.maps.build import rasterize
from tfloc.maps.walls import run_extents
from tfloc.tfplus.cost import see_through
from tfloc.tfplus.matcher import TfPlusConfig, TurningFunctionPlusMatcher, _field
from tfloc.tfplus.refine import RefineConfig, refine, refine_to_field
from tfloc.tfplus.view import map_view

RES = 0.05


def wall_grid(thick_cells: int) -> GridMap:
    """A 3 m × 1 m strip: free for x < 1 m, a wall of ``thick_cells`` cells from x = 1 m, free
    behind it (unknown is irrelevant here), in 5 cm cells with the origin at (0, 0)."""
    occ = np.zeros((20, 60), dtype=np.float32)
    occ[:, 20:20 + thick_cells] = 1.0
    return GridMap(occ, RES, (0.0, 0.0))


ONE_BEAM = LaserSpec.from_degrees(10.0, 0.0, 1.0, 0.0)


@pytest.fixture(scope="module")
def room() -> VectorMap:
    """A 6 × 4 m room with a pillar and a cabinet, so every direction is constrained."""
    return VectorMap(outline=box(0, 0, 6, 4), obstacles=(box(2.0, 1.4, 2.4, 1.8), box(4.6, 0.0, 5.4, 0.5)),
                     name="room")


def thick_grid(vmap: VectorMap, cells: int) -> GridMap:
    """``vmap`` rasterised at 5 cm with its occupied cells dilated by ``cells`` cells either side
    (walls ``2 cells + 1`` thick, centred on the true wall lines)."""
    g = rasterize(vmap, RES)
    occ = np.array(g.occupancy, dtype=np.float32)
    if cells:
        occ[binary_dilation(g.occupied, iterations=cells)] = 1.0
    return GridMap(occ, g.resolution, g.origin, name=f"{vmap.name}+{cells}")


def test_grid_ray_stops_at_the_first_cell_of_a_thick_wall():
    # the bias this work starts from: the ray ends in the wall's first cell, whatever its thickness
    for cells in (1, 3, 5):
        r = wall_grid(cells).raycast(Pose(0.5, 0.52, 0.0), ONE_BEAM)[0]
        assert r == pytest.approx(0.525)       # the middle of the first cell's chord (1.00–1.05 m)


def test_see_through_march_ends_at_the_far_side_of_a_thick_wall():
    grid, pose = wall_grid(3), np.array([[0.5, 0.52, 0.0]])      # wall from 1.00 to 1.15 m
    far_side = 0.65                                               # metres from the sensor
    for real, through in ((0.52, False), (0.60, False), (far_side + 0.09, False),
                          (far_side + 0.11, True), (3.0, True)):
        got = see_through(grid, ONE_BEAM, np.array([real]), pose, 0.1)[0, 0]
        assert got == through, real
    # no return where the beam meets a wall within range: seen through; none in range: not
    assert see_through(grid, ONE_BEAM, np.array([np.inf]), pose, 0.1)[0, 0]
    assert not see_through(wall_grid(0), ONE_BEAM, np.array([np.inf]), pose, 0.1)[0, 0]
    # the rule before: anything 5 cm beyond the first cell counted, returns inside the wall too
    v = grid.raycast(pose, ONE_BEAM)
    assert (np.array([0.60]) > v + 0.05).all()


def test_run_extents_find_both_surfaces_of_a_thick_wall():
    grid = wall_grid(3)                                           # occupied x in [1.00, 1.15)
    centres = np.array([[1.025, 0.525], [1.075, 0.525], [1.125, 0.525], [0.525, 0.525]])
    normals = np.tile([[-1.0, 0.0]], (4, 1))                      # facing the free side
    plus, minus = run_extents(centres, normals, grid.occupied, np.zeros(2), RES)
    step = RES / 3
    # the surface facing the sensor at x = 1.00 m, the back at 1.15 m, each to within a step
    np.testing.assert_allclose(centres[:3, 0] - plus[:3] - step / 2, 1.0, atol=step / 2 + 1e-9)
    np.testing.assert_allclose(centres[:3, 0] + minus[:3] + step / 2, 1.15, atol=step / 2 + 1e-9)
    assert plus[3] == minus[3] == 0.0                             # not in a wall
    capped, _ = run_extents(centres, normals, wall_grid(40).occupied, np.zeros(2), RES, 0.3)
    assert capped.max() <= 0.3


def test_pooled_field_bounds_every_translation_within_half_a_step(room):
    f = map_view(room, 0.05, 0.3, 0.0)
    low = map_view(room, 0.05, 0.3, 0.0, pool=0.1)
    rng = np.random.default_rng(1)
    xy = rng.uniform([0.3, 0.3], [5.7, 3.7], (300, 2))
    for d in rng.uniform(-0.095, 0.095, (20, 2)):
        assert np.all(low(xy) <= f(xy + d) + 1e-6)
    near = f(xy) < 0.3
    assert np.mean(low(xy)[near] < f(xy)[near]) > 0.5          # and it is a real relaxation


@pytest.mark.parametrize("cells", [0, 1, 2])
def test_refinement_to_the_map_is_unbiased_on_thick_walls(room, cells):
    laser = LaserSpec.from_degrees(10.0, 180.0, 1.0, -90.0)
    grid = thick_grid(room, cells)
    field = map_view(grid, 0.05, 0.3, 0.3)
    rng = np.random.default_rng(cells)
    errs_field, errs_virtual = [], []
    for true in (Pose(1.2, 2.1, 0.3), Pose(3.3, 2.6, -2.4), Pose(4.1, 1.4, 1.9)):
        ranges = room.raycast(true, laser) + rng.normal(0, 0.01, laser.n_beams)   # returns on the
        pts = laser.to_points(ranges)                                          # true wall lines
        start = true.as_array() + np.array([[0.08, -0.05, math.radians(2)], [-0.06, 0.07, -math.radians(2)]])
        for out in refine_to_field(field, pts, start, RefineConfig(prune_after=0)):
            errs_field.append(math.hypot(out[0] - true.x, out[1] - true.y))
        for out in refine(grid, laser, pts, start, RefineConfig(prune_after=0)):
            errs_virtual.append(math.hypot(out[0] - true.x, out[1] - true.y))
    assert max(errs_field) < 0.03, errs_field
    if cells == 2:   # the virtual scan is ~12 cm short here, and the refinement follows it
        assert np.median(errs_virtual) > 0.05, errs_virtual


def test_tf_plus_localizes_on_a_thick_walled_grid_with_a_361_beam_scanner(room):
    laser = LaserSpec.from_degrees(30.0, 180.0, 0.5, -90.0)
    grid = thick_grid(room, 2)
    true = Pose(1.6, 2.4, 0.2)
    ranges = room.raycast(true, laser) + np.random.default_rng(4).normal(0, 0.01, laser.n_beams)
    init = Pose(true.x + 0.9, true.y - 0.4, true.theta + math.radians(9))
    est = tfloc.localize(grid, laser, ranges, init, matcher="tf-plus")
    assert est.pose.distance_to(true) < 0.03
    assert abs(tfloc.angdiff(est.pose.theta, true.theta)) < math.radians(0.5)
    before = TurningFunctionPlusMatcher(refine_to="virtual", select="virtual").localize(
        Problem(grid, laser, ranges, init))
    assert before.pose.distance_to(true) > est.pose.distance_to(true)


def test_field_knows_a_grid_from_a_vector_map(room):
    cfg = TfPlusConfig()
    assert _field(thick_grid(room, 1), cfg).faces
    assert not _field(room, cfg).faces
    assert not map_view(thick_grid(room, 1), 0.05, 0.3, 0.0).faces
