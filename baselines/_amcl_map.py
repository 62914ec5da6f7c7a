# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""The map as Nav2's AMCL holds it (``map_t``: ``nav2_amcl/include/nav2_amcl/map/map.hpp``,
``AmclNode::convertMap``), shared by ``amcl`` (the port) and ``amcl-wheel``.

* The grid AMCL runs on: a :class:`~tfloc.maps.grid.GridMap` as given, a vector map rasterised at
  5 cm (as a user exports it for Nav2).
* Cells in map_server's trinary states (``occ_state``: -1 free, 0 unknown, +1 occupied), indexed
  ``[j, i]`` = Nav2's ``MAP_INDEX(i, j)``; Nav2's ``origin_x`` is the grid's corner plus
  ``(size_x / 2) · scale`` (integer division), so ``MAP_GXWX(x) = floor((x − origin_x)/scale +
  0.5) + size_x / 2`` puts cell ``i`` *around* ``corner + i · scale``: half a cell from where
  map_server draws it. Kept, as Nav2 does it.
* The free cells in ``createFreeSpaceVector``'s order (``i`` outer, ``j`` inner): what the uniform
  pose generator draws from.
* ``occ_dist``: the likelihood field's distance to the nearest occupied cell (metres, float32,
  capped at ``laser_likelihood_max_dist``), which ``map_update_cspace`` computes by a brushfire;
  here it is tfloc's one distance field (:mod:`tfloc.maps.fields`, exact Euclidean distances
  between cell centres), whose cells are the grid's own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tfloc.core.map import Map
from tfloc.maps.build import rasterize
from tfloc.maps.cache import cached
from tfloc.maps.fields import distance_field
from tfloc.maps.grid import GridMap

#: Grid resolution (m) a vector map is rasterised at, as a user would export it for Nav2
VECTOR_MAP_RESOLUTION = 0.05


def amcl_grid(map_: Map) -> GridMap:
    """The grid AMCL runs on: ``map_`` itself if it is a grid, else rasterised at 5 cm (cached per map)."""
    if isinstance(map_, GridMap):
        return map_
    return cached(map_, ("amcl-grid", VECTOR_MAP_RESOLUTION), lambda: rasterize(map_, VECTOR_MAP_RESOLUTION))


@dataclass(frozen=True, eq=False)
class NavMap:
    """Nav2's ``map_t`` of a grid (module notes); metres.

    Attributes:
        occ_state: ``(size_y, size_x)`` int8, -1 free, 0 unknown, +1 occupied.
        scale: cell size (m).
        origin_x, origin_y: Nav2's origin, the grid's corner + ``(size // 2) · scale`` (m).
        free_cells: ``(F, 2)`` int64 ``(i, j)`` of the free cells, ``i`` outer, ``j`` inner.
    """

    occ_state: np.ndarray
    scale: float
    origin_x: float
    origin_y: float
    free_cells: np.ndarray

    @property
    def size_x(self) -> int:
        return int(self.occ_state.shape[1])

    @property
    def size_y(self) -> int:
        return int(self.occ_state.shape[0])

    @property
    def geometry(self) -> tuple[float, float, float, int, int]:
        """``(origin_x, origin_y, scale, size_x, size_y)``: what the kernels take."""
        return self.origin_x, self.origin_y, self.scale, self.size_x, self.size_y


def _build_nav_map(grid: GridMap) -> NavMap:
    occ = np.zeros(grid.shape, dtype=np.int8)
    occ[grid.free] = -1
    occ[grid.occupied] = 1
    H, W = grid.shape
    scale = float(grid.resolution)
    free = np.column_stack(np.nonzero(occ.T == -1)).astype(np.int64)  # (i, j), i outer
    return NavMap(np.ascontiguousarray(occ), scale, grid.origin[0] + (W // 2) * scale,
                  grid.origin[1] + (H // 2) * scale, np.ascontiguousarray(free))


def nav_map(grid: GridMap) -> NavMap:
    """The :class:`NavMap` of ``grid`` (built once per grid)."""
    return cached(grid, "amcl-nav-map", lambda: _build_nav_map(grid))


def _cell_block(grid: GridMap, max_occ_dist: float) -> np.ndarray:
    field = distance_field(grid, grid.resolution, max_occ_dist)
    res = grid.resolution
    at = (np.asarray(grid.origin) + 0.5 * res - np.asarray(field.origin)) / res
    off = np.rint(at).astype(np.int64)
    H, W = grid.shape
    if (np.abs(at - off).max() > 1e-6 or off.min() < 0 or off[1] + H > field.shape[0]
            or off[0] + W > field.shape[1]):  # the field's lattice is the grid's own (fields.lattice_anchor)
        raise AssertionError(f"{grid.name}: distance field not on the grid's cells")
    out = np.ascontiguousarray(field.distance[off[1]:off[1] + H, off[0]:off[0] + W], dtype=np.float32)
    out.setflags(write=False)
    return out


def occ_dist(grid: GridMap, max_occ_dist: float) -> np.ndarray:
    """``(size_y, size_x)`` float32: each cell's distance (m) to the nearest occupied cell, capped
    at ``max_occ_dist`` (Nav2's ``cells[].occ_dist``), built once per grid and cap."""
    return cached(grid, ("amcl-occ-dist", round(float(max_occ_dist), 9)),
                  lambda: _cell_block(grid, max_occ_dist))
