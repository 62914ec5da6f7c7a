# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/map/map.c`` and ``include/nav2_amcl/map/map.hpp`` (``map_t``, the
``MAP_*`` macros) with ``AmclNode::convertMap`` and ``createFreeSpaceVector`` of ``amcl_node.cpp``:
the map as Nav2's AMCL holds it. Metres.

* Cells in map_server's trinary states (``occ_state``: -1 free, 0 unknown, +1 occupied), indexed
  ``[j, i]`` = Nav2's ``MAP_INDEX(i, j)``; Nav2's ``origin_x`` is the grid's corner plus
  ``(size_x / 2) · scale`` (integer division), so ``MAP_GXWX(x) = floor((x − origin_x)/scale +
  0.5) + size_x / 2`` puts cell ``i`` *around* ``corner + i · scale``: half a cell from where
  map_server draws it. Kept, as Nav2 does it.
* The free cells in ``createFreeSpaceVector``'s order (``i`` outer, ``j`` inner): what the uniform
  pose generator draws from.

The grid itself (a grid map as given, a vector map rasterised at 5 cm) is
:func:`tfloc.baselines._amcl_common.amcl_grid`, shared with ``amcl-wheel``; the likelihood
field's distances (``map_cspace.cpp``) are :mod:`.map_cspace`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tfloc.maps.cache import cached
from tfloc.maps.grid import GridMap


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
