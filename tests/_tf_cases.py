"""Shared cases of the `tf` and `tf-plus` tests: the pose both recover in the test room, a noisy
scan, and the degenerate problems (a scan of one or two returns, a corridor seen end-on)."""

from __future__ import annotations

import numpy as np
from shapely.geometry import box

from tfloc import LaserSpec, Map, Pose, Problem, VectorMap

TRUE = Pose(3.0, 3.5, 0.4)


def noisy_scan(m: Map, laser: LaserSpec, pose: Pose, seed: int = 0) -> np.ndarray:
    """The ranges ``m`` gives at ``pose`` + N(0, 1 cm) noise."""
    return m.raycast(pose, laser) + np.random.default_rng(seed).normal(0, 0.01, laser.n_beams)


def cost_cases(room: Map, laser: LaserSpec, grid: bool, n: int = 4):
    """The selection cost's test scans: ``(map, view, ranges)`` for ``n`` noisy scans of ``room``
    from :data:`TRUE` with no-return beams (every 17th) and beams seen through a wall (5-8), the
    map the room or its 5 cm raster (``grid``), the view at 5 cm truncated at 0.3 m."""
    from tfloc.maps.build import rasterize
    from tfloc.tfplus.view import map_view

    m = rasterize(room, 0.05) if grid else room
    field = map_view(m, 0.05, 0.3, 0.3)
    for seed in range(n):
        ranges = noisy_scan(room, laser, TRUE, seed)
        ranges[::17] = np.inf
        ranges[5:9] += 0.5
        yield m, field, ranges


def few_returns_problem(laser: LaserSpec, returns: int) -> Problem:
    """A scan with only ``returns`` returns (2 m, from beam 90) in a 4 × 3 m room, guess (1, 1, 0)
    in floats, as a dataset's poses are (int coordinates would compile tf-plus's kernels again)."""
    ranges = np.full(laser.n_beams, np.inf)
    ranges[90:90 + returns] = 2.0
    room = VectorMap(outline=box(0, 0, 4, 3))
    return Problem(room, laser, ranges, Pose(1.0, 1.0, 0.0))


def corridor_problem(laser: LaserSpec) -> Problem:
    """A 30 × 1 m corridor seen end-on from (5, 0.5, 0); the guess is (5.3, 0.5, 0.05)."""
    corridor = VectorMap(outline=box(0, 0, 30, 1.0))
    ranges = corridor.raycast(Pose(5, 0.5, 0.0), laser)
    return Problem(corridor, laser, ranges, Pose(5.3, 0.5, 0.05))
