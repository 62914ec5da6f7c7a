"""karto's base scans: on a grid, a beam ends in the middle of the occupied run it enters
(``run-centre``), not on the wall's near face; thickening a wall on both sides leaves it there."""

from __future__ import annotations

import numpy as np
import pytest
from tfloc.baselines._scan_lattice import ring_laser, run_centre_ranges, scan_lattice

from tfloc.maps.grid import GridMap
from tfloc.maps.styles import thickened
from tfloc.maps.vector import VectorMap


def _wall_grid(thickness_cells: int) -> GridMap:
    """Free space with a wall along x, its middle at x = 3.025 m (cells of 5 cm from x = 0)."""
    occ = np.zeros((80, 100), dtype=np.float32)
    half = thickness_cells // 2
    occ[:, 60 - half: 60 - half + thickness_cells] = 1.0
    return GridMap(occ, 0.05, (0.0, 0.0), 0.25, 0.1)


@pytest.mark.parametrize("cells", [1, 3, 5])
def test_a_beam_ends_in_the_middle_of_the_wall(cells: int) -> None:
    g = _wall_grid(cells)
    laser = ring_laser(10.0, 90.0)              # beams at -180, -90, 0, 90 degrees
    pose = np.array([[1.0, 2.0, 0.0]])
    near = g.raycast(pose, laser)
    mid = run_centre_ranges(g, pose, laser, near)
    assert mid[0, 2] == pytest.approx(3.025 - 1.0, abs=0.013)          # the wall's middle, ± a quarter cell
    assert near[0, 2] == pytest.approx(3.025 - 1.0 - 0.05 * (cells // 2), abs=0.013)
    assert np.isinf(mid[0, [0, 1, 3]]).all()                            # no return stays none


def test_thickening_moves_the_near_face_not_the_centre() -> None:
    g = _wall_grid(1)
    laser = ring_laser(10.0, 1.0)
    pose = np.array([[1.0, 2.0, 0.3]])
    near0 = g.raycast(pose, laser)
    mid0 = run_centre_ranges(g, pose, laser, near0)
    for k in (1, 2):
        t = thickened(g, k)
        near = t.raycast(pose, laser)
        both = np.isfinite(near0) & np.isfinite(near)
        assert both.sum() > 60
        diff = np.abs(run_centre_ranges(t, pose, laser, near)[both] - mid0[both])
        assert np.quantile(diff, 0.95) < 0.02 and diff.max() < 0.1    # a few grazing beams at the edge
        assert np.median(near0[both] - near[both]) > 0.05 * k - 0.01     # the near face moved


def test_lattice_uses_the_surface_on_grids_only() -> None:
    g = _wall_grid(5)
    near = scan_lattice(g, 1.0, 0.2, 10.0, 1.0, "near-face")
    mid = scan_lattice(g, 1.0, 0.2, 10.0, 1.0, "run-centre")
    idx = np.arange(min(3, len(near.positions)))
    assert (mid.ranges(idx)[np.isfinite(mid.ranges(idx))] >= near.ranges(idx)[np.isfinite(near.ranges(idx))] - 1e-9).all()
    assert not np.allclose(mid.ranges(idx), near.ranges(idx))
    v = VectorMap.from_segments(np.array([[3.0, -5.0, 3.0, 5.0]]))
    a = scan_lattice(v, 1.0, 0.2, 10.0, 1.0, "near-face")
    b = scan_lattice(v, 1.0, 0.2, 10.0, 1.0, "run-centre")
    if len(a.positions):
        i = np.arange(len(a.positions))
        np.testing.assert_array_equal(a.ranges(i), b.ranges(i))


def test_cv_corners_virtual_surface_option() -> None:
    from tfloc.baselines.cv_corners import CvCornersMatcher

    from tfloc.core.laser import LaserSpec
    from tfloc.core.pose import Pose
    from tfloc.core.problem import Problem

    g, laser, pose = _wall_grid(5), LaserSpec.from_degrees(10.0, 180.0, 1.0), Pose(1.0, 2.0, 0.0)
    problem = Problem(g, laser, g.raycast(pose, laser), pose)
    near = CvCornersMatcher()._virtual(pose, problem)
    mid = CvCornersMatcher(virtual_surface="run-centre")._virtual(pose, problem)
    np.testing.assert_array_equal(near, g.raycast(pose, laser))
    assert mid[90] == pytest.approx(3.025 - 1.0, abs=0.013) and near[90] == pytest.approx(1.925, abs=0.013)
