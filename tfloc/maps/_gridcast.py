"""Compiled grid traversal (Amanatides–Woo DDA) behind :class:`GridMap` (numba, one core).

All coordinates here are in cell units: ``(x, y)`` = (column, row) with cell ``(i, j)`` covering
``[i, i+1) × [j, j+1)``; ``grid[j, i]`` is row ``j`` (y), column ``i`` (x).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def inside_kernel(xy: np.ndarray, origin_x: float, origin_y: float, resolution: float, W: int,
                  H: int) -> np.ndarray:
    """Which ``(N, 2)`` world points (metres) lie in a cell of the ``H × W`` grid whose cell
    ``[0, 0]`` has its outer corner at the origin: ``0 ≤ (x − origin_x) / resolution < W`` and
    the same in y, which is ``0 ≤ ⌊(x − origin_x) / resolution⌋ < W`` (false for NaN)."""
    out = np.empty(xy.shape[0], dtype=np.bool_)
    for k in range(xy.shape[0]):
        u = (xy[k, 0] - origin_x) / resolution
        v = (xy[k, 1] - origin_y) / resolution
        out[k] = u >= 0.0 and u < W and v >= 0.0 and v < H
    return out


@njit(cache=True, nogil=True)
def _slab(p0: float, d: float, size: int, t0: float, t1: float) -> tuple[float, float]:
    """``[t0, t1]`` narrowed to the ray parameters with ``0 ≤ p0 + t·d < size`` on one axis
    (empty, ``(inf, -inf)``, when a ray parallel to the axis lies outside)."""
    if d == 0.0:
        if p0 < 0.0 or p0 >= size:
            return np.inf, -np.inf
        return t0, t1
    a, b = -p0 / d, (size - p0) / d
    return max(t0, min(a, b)), min(t1, max(a, b))


@njit(cache=True, nogil=True)
def _entry(x0: float, y0: float, dx: float, dy: float, W: int, H: int) -> tuple[float, float]:
    """Ray parameter interval ``[t0, t1]`` (cell units) inside the box ``[0, W] × [0, H]``."""
    t0, t1 = _slab(x0, dx, W, 0.0, np.inf)
    return _slab(y0, dy, H, t0, t1)  # an empty interval stays empty


@njit(cache=True, nogil=True)
def _start(x0: float, y0: float, dx: float, dy: float, t0: float, W: int, H: int):
    """DDA state where the ray enters the grid at parameter ``t0``: the cell ``(i, j)``, the steps
    ``(sx, sy)``, the parameter per cell ``(tdx, tdy)`` and the next x/y cell crossings ``(tx, ty)``."""
    x, y = x0 + t0 * dx, y0 + t0 * dy
    i, j = min(max(int(np.floor(x)), 0), W - 1), min(max(int(np.floor(y)), 0), H - 1)
    sx = 1 if dx > 0 else -1
    sy = 1 if dy > 0 else -1
    tdx = abs(1.0 / dx) if dx != 0.0 else np.inf
    tdy = abs(1.0 / dy) if dy != 0.0 else np.inf
    tx = t0 + ((i + 1 - x) / dx if dx > 0 else (x - i) / -dx) if dx != 0.0 else np.inf
    ty = t0 + ((j + 1 - y) / dy if dy > 0 else (y - j) / -dy) if dy != 0.0 else np.inf
    return i, j, sx, sy, tdx, tdy, tx, ty


@njit(cache=True, nogil=True)
def _step(i: int, j: int, sx: int, sy: int, tdx: float, tdy: float, tx: float, ty: float,
          W: int, H: int):
    """One DDA step into the next cell across the nearer of the crossings ``(tx, ty)``: the new
    ``(i, j, tx, ty)`` and whether that cell lies inside the ``W × H`` grid."""
    if tx < ty:
        i += sx
        return i, j, tx + tdx, ty, 0 <= i < W
    j += sy
    return i, j, tx, ty + tdy, 0 <= j < H


@njit(cache=True, nogil=True)
def _march(occ: np.ndarray, x0: float, y0: float, dx: float, dy: float, tmax: float) -> float:
    """Distance (cell units) along the unit ray to the first occupied cell, ``inf`` if none before
    ``tmax``. The hit is the midpoint of the ray's chord through that cell (an unbiased estimate of
    a surface lying anywhere in the cell)."""
    H, W = occ.shape
    t0, t1 = _entry(x0, y0, dx, dy, W, H)
    if t0 > t1 or t0 > tmax:
        return np.inf
    t1 = min(t1, tmax)
    i, j, sx, sy, tdx, tdy, tx, ty = _start(x0, y0, dx, dy, t0, W, H)
    t = t0
    while t <= t1:
        tn = min(tx, ty)
        if occ[j, i]:
            hit = 0.5 * (t + tn)
            return hit if hit <= tmax else np.inf
        t = tn
        i, j, tx, ty, inside = _step(i, j, sx, sy, tdx, tdy, tx, ty, W, H)
        if not inside:
            break
    return np.inf


@njit(cache=True, nogil=True)
def raycast_grid(poses: np.ndarray, rel_angles: np.ndarray, occ: np.ndarray, ox: float, oy: float,
                 res: float, max_range: float) -> np.ndarray:
    """Ranges (metres) from each world pose ``(P, 3)`` along each beam ``(B,)`` to the first
    occupied cell of ``occ`` ``(H, W)`` (bool), grid origin ``(ox, oy)`` m, cell size ``res`` m.
    No hit before ``max_range`` gives ``inf``."""
    P, B = poses.shape[0], rel_angles.shape[0]
    out = np.full((P, B), np.inf)
    tmax = max_range / res
    for p in range(P):
        x0, y0 = (poses[p, 0] - ox) / res, (poses[p, 1] - oy) / res
        for b in range(B):
            a = poses[p, 2] + rel_angles[b]
            t = _march(occ, x0, y0, np.cos(a), np.sin(a), tmax)
            if t < tmax:
                out[p, b] = t * res
    return out


@njit(cache=True, nogil=True)
def carve_grid(passes: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> None:
    """Add 1 to ``passes[j, i]`` for every cell a segment crosses from ``starts`` to ``ends``
    (``(K, 2)``, cell units), the end cell excluded (it holds the hit). In place."""
    H, W = passes.shape
    for k in range(starts.shape[0]):
        x0, y0 = starts[k, 0], starts[k, 1]
        ex, ey = ends[k, 0] - x0, ends[k, 1] - y0
        length = np.hypot(ex, ey)
        if length == 0.0:
            continue
        dx, dy = ex / length, ey / length
        t0, t1 = _entry(x0, y0, dx, dy, W, H)
        if t0 > t1:
            continue
        t1 = min(t1, length)
        i, j, sx, sy, tdx, tdy, tx, ty = _start(x0, y0, dx, dy, t0, W, H)
        ie, je = int(np.floor(ends[k, 0])), int(np.floor(ends[k, 1]))
        t = t0
        while t < t1:
            if i == ie and j == je:
                break
            passes[j, i] += 1
            t = tx if tx < ty else ty
            i, j, tx, ty, inside = _step(i, j, sx, sy, tdx, tdy, tx, ty, W, H)
            if not inside:
                break
