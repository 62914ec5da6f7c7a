# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/map/map_cspace.cpp`` (``map_update_cspace``): the likelihood
field's distance from each cell to the nearest occupied cell (metres, float32, capped at
``laser_likelihood_max_dist``), Nav2's ``cells[].occ_dist``.

Departure: ``map_update_cspace`` computes it by a brushfire over the cells; here it is tfloc's one
distance field (:mod:`tfloc.maps.fields`, exact Euclidean distances between cell centres), whose
cells are the grid's own (``tests/baselines/test_amcl.py`` compares it with a brushfire).
"""

from __future__ import annotations

import numpy as np

from tfloc.maps.cache import cached
from tfloc.maps.fields import distance_field
from tfloc.maps.grid import GridMap


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
