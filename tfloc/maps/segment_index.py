"""Buckets of a vector map's segments on a coarse grid, so that a ray cast finds the segments
within range of a pose without testing every segment of the map.

The segment ray-caster (:mod:`tfloc.maps._raycast`) starts each cast by collecting the segments
closer than the scanner's range. Tested one by one that is O(M) per pose, so a scan's cost grew
with the map (measured in ``docs/scaling.md``). With the buckets a cast looks only at the cells
within range; the set of segments found, and so every range, is the same
(``tests/maps/test_kernels_raycast.py``).

An index is the tuple ``(x0, y0, inv_cell, nx, ny, start, items)``: cell ``(i, j)`` (column,
row; ``cell = 1 / inv_cell`` metres from ``(x0, y0)``) holds the segments ``items[start[c]:
start[c + 1]]`` with ``c = j·nx + i``, every segment in each cell its bounding box overlaps.
:data:`NO_INDEX` (``nx = 0``) means "test every segment"; small maps use it (below
:data:`MIN_SEGMENTS` segments the linear test is as fast).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

MIN_SEGMENTS = 512   # maps with fewer segments are scanned linearly (no index)
CELLS_PER_RANGE = 4  # cells per scanner range along each axis (a cast visits ~(2·4+1)² cells)

#: The index that makes a cast test every segment.
NO_INDEX = (0.0, 0.0, 0.0, 0, 0, np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64))


def build_index(segs: np.ndarray, max_range: float) -> tuple:
    """The buckets of ``segs`` ``(M, 4)`` for casts of range ``max_range`` (metres): cells of
    ``max_range / CELLS_PER_RANGE`` (at least 0.5 m); :data:`NO_INDEX` for fewer than
    :data:`MIN_SEGMENTS` segments or an unbounded range."""
    segs = np.ascontiguousarray(segs, dtype=float)
    if len(segs) < MIN_SEGMENTS or not np.isfinite(max_range) or max_range <= 0:
        return NO_INDEX
    cell = max(0.5, float(max_range) / CELLS_PER_RANGE)
    x0 = float(min(segs[:, 0].min(), segs[:, 2].min())) - cell
    y0 = float(min(segs[:, 1].min(), segs[:, 3].min())) - cell
    nx = int(math.ceil((max(segs[:, 0].max(), segs[:, 2].max()) - x0) / cell)) + 2
    ny = int(math.ceil((max(segs[:, 1].max(), segs[:, 3].max()) - y0) / cell)) + 2
    start, items = _buckets(segs, x0, y0, 1.0 / cell, nx, ny)
    start.setflags(write=False)
    items.setflags(write=False)
    return (x0, y0, 1.0 / cell, np.int64(nx), np.int64(ny), start, items)


@njit(cache=True, nogil=True)
def _box(seg: np.ndarray, x0: float, y0: float, inv: float, nx: int,
         ny: int) -> tuple[int, int, int, int]:
    """The cells ``(i0, i1, j0, j1)`` (inclusive) the segment's bounding box overlaps."""
    i0 = min(max(int(math.floor((min(seg[0], seg[2]) - x0) * inv)), 0), nx - 1)
    i1 = min(max(int(math.floor((max(seg[0], seg[2]) - x0) * inv)), 0), nx - 1)
    j0 = min(max(int(math.floor((min(seg[1], seg[3]) - y0) * inv)), 0), ny - 1)
    j1 = min(max(int(math.floor((max(seg[1], seg[3]) - y0) * inv)), 0), ny - 1)
    return i0, i1, j0, j1


@njit(cache=True, nogil=True)
def _buckets(segs: np.ndarray, x0: float, y0: float, inv: float, nx: int,
             ny: int) -> tuple[np.ndarray, np.ndarray]:
    """``start`` ``(nx·ny + 1,)`` and ``items``: each segment in every cell its box overlaps,
    in segment order within a cell."""
    counts = np.zeros(nx * ny + 1, dtype=np.int64)
    for m in range(segs.shape[0]):
        i0, i1, j0, j1 = _box(segs[m], x0, y0, inv, nx, ny)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                counts[j * nx + i + 1] += 1
    for c in range(nx * ny):
        counts[c + 1] += counts[c]
    items = np.empty(counts[nx * ny], dtype=np.int64)
    fill = counts[:-1].copy()
    for m in range(segs.shape[0]):
        i0, i1, j0, j1 = _box(segs[m], x0, y0, inv, nx, ny)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                items[fill[j * nx + i]] = m
                fill[j * nx + i] += 1
    return counts, items


@njit(cache=True, nogil=True)
def candidates(index: tuple, ox: float, oy: float, reach: float, seen: np.ndarray,
               stamp: int, out: np.ndarray) -> int:
    """The segments whose cells lie within ``reach`` (metres, along each axis) of ``(ox, oy)``,
    each once, into ``out``; returns their count. ``seen`` ``(M,)`` marks the segments already
    taken with ``stamp`` (a value no earlier call of the same ``seen`` used)."""
    x0, y0, inv, nx, ny, start, items = index
    i0 = min(max(int(math.floor((ox - reach - x0) * inv)), 0), nx - 1)
    i1 = min(max(int(math.floor((ox + reach - x0) * inv)), 0), nx - 1)
    j0 = min(max(int(math.floor((oy - reach - y0) * inv)), 0), ny - 1)
    j1 = min(max(int(math.floor((oy + reach - y0) * inv)), 0), ny - 1)
    k = 0
    for j in range(j0, j1 + 1):
        for i in range(i0, i1 + 1):
            c = j * nx + i
            for t in range(start[c], start[c + 1]):
                m = items[t]
                if seen[m] != stamp:
                    seen[m] = stamp
                    out[k] = m
                    k += 1
    return k
