# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/map/map_range.c`` (``map_calc_range``): the range from a pose to
the first cell that is not free, by Bresenham over the cells (unknown and off-map cells stop the
beam, as occupied ones), what the beam model expects (:mod:`tfloc.baselines.amcl.sensors.laser.beam_model`).
Compiled with numba; geometry arguments are :attr:`~tfloc.baselines.amcl.map.map.NavMap.geometry`.
Metres, radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _free(occ: np.ndarray, i: int, j: int, size_x: int, size_y: int) -> bool:
    """Whether a beam passes cell ``(i, j)``: on the map and free (``occ_state == -1``)."""
    return i >= 0 and i < size_x and j >= 0 and j < size_y and occ[j, i] == -1


@njit(cache=True, nogil=True)
def calc_range(occ: np.ndarray, origin_x: float, origin_y: float, scale: float, size_x: int,
               size_y: int, ox: float, oy: float, oa: float, max_range: float) -> float:
    """``map_calc_range``: the range (m) from ``(ox, oy)`` along heading ``oa`` to the first cell
    that is not free (Bresenham; cell distance × scale), or ``max_range``."""
    x0 = int(math.floor((ox - origin_x) / scale + 0.5) + size_x // 2)
    y0 = int(math.floor((oy - origin_y) / scale + 0.5) + size_y // 2)
    x1 = int(math.floor((ox + max_range * math.cos(oa) - origin_x) / scale + 0.5) + size_x // 2)
    y1 = int(math.floor((oy + max_range * math.sin(oa) - origin_y) / scale + 0.5) + size_y // 2)
    if abs(y1 - y0) > abs(x1 - x0):  # steep: step along y (Nav2 swaps the axes, the same cells)
        return _bresenham(occ.T, y0, x0, y1, x1, size_y, size_x, scale, max_range)
    return _bresenham(occ, x0, y0, x1, y1, size_x, size_y, scale, max_range)


@njit(cache=True, nogil=True)
def _bresenham(occ: np.ndarray, x0: int, y0: int, x1: int, y1: int, size_x: int, size_y: int,
               scale: float, max_range: float) -> float:
    """``map_calc_range``'s loop along x (``occ[y, x]``; the transposed grid for a steep beam)."""
    deltax = abs(x1 - x0)
    deltay = abs(y1 - y0)
    error = 0
    deltaerr = deltay
    x = x0
    y = y0
    xstep = 1 if x0 < x1 else -1
    ystep = 1 if y0 < y1 else -1
    if not _free(occ, x, y, size_x, size_y):
        return math.sqrt((x - x0) * (x - x0) + (y - y0) * (y - y0)) * scale
    while x != (x1 + xstep * 1):
        x += xstep
        error += deltaerr
        if 2 * error >= deltax:
            y += ystep
            error -= deltax
        if not _free(occ, x, y, size_x, size_y):
            return math.sqrt((x - x0) * (x - x0) + (y - y0) * (y - y0)) * scale
    return max_range
