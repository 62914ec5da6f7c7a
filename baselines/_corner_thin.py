"""Drop ShortStraw corners that range noise made: a corner whose neighbours are joined by raw
scan points lying on one straight line (every point within a tolerance of the chord) is no corner.

At a resampling distance of a few centimetres ShortStraw's straws see the range noise itself: a
straight wall scanned from close by (raw points ~1–2 cm apart, σ ≈ 1 cm) gets a corner every few
centimetres, on real 0.5° scans dozens per scan. This is Alg. 3's "is the path from c_l to c_n a
line?" asked of the raw points with a noise-sized tolerance instead of the chord/path ratio of the
resampled points, which noise pushes below 0.95 on a straight wall. The test is on the largest
deviation, not the RMS: a small real feature (a door frame 5 cm deep on a 1 m wall) moves few
points far, which an RMS averages away.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _nearest_indices(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    k, n = corners.shape[0], points.shape[0]
    idx = np.zeros(k, dtype=np.int64)
    for c in range(k):
        best = np.inf
        for j in range(n):
            dx, dy = points[j, 0] - corners[c, 0], points[j, 1] - corners[c, 1]
            d2 = dx * dx + dy * dy
            if d2 < best:
                best, idx[c] = d2, j
        if c > 0 and idx[c] < idx[c - 1]:
            idx[c] = idx[c - 1]
    return idx


def corner_indices(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """For each corner (``(K, 2)``, in scan order) the index of the nearest raw point ``(N, 2)``
    (in beam order; the first on a tie), made non-decreasing so that consecutive corners bound a
    run of points."""
    return _nearest_indices(np.ascontiguousarray(corners, dtype=float), np.ascontiguousarray(points, dtype=float))


@njit(cache=True, nogil=True)
def _keep_mask(corners: np.ndarray, points: np.ndarray, idx: np.ndarray, tol: float) -> np.ndarray:
    k = corners.shape[0]
    keep = np.zeros(k, dtype=np.bool_)
    keep[0] = True
    keep[k - 1] = True
    last, mid = 0, 1
    for nxt in range(2, k):
        ax, ay = corners[last, 0], corners[last, 1]
        ux, uy = corners[nxt, 0] - ax, corners[nxt, 1] - ay
        length = math.sqrt(ux * ux + uy * uy)
        straight = False
        if length > 0.0:
            ux, uy = ux / length, uy / length
            straight = True
            for j in range(idx[last], idx[nxt] + 1):
                if abs((points[j, 0] - ax) * uy - (points[j, 1] - ay) * ux) > tol:
                    straight = False
                    break
        if straight:
            mid = nxt          # drop the middle corner; the next one becomes the middle
        else:
            keep[mid] = True
            last, mid = mid, nxt
    return keep


def drop_straight_corners(corners: np.ndarray, points: np.ndarray, tol: float) -> np.ndarray:
    """Corners ``(K, 2)`` (metres, scan order) without those lying on a straight run of the raw
    points ``(N, 2)`` (beam order, no-return beams removed).

    One pass over consecutive triples (last kept, middle, next), as Alg. 3: the middle corner is
    dropped when every raw point from the last kept corner to the next lies within ``tol`` metres
    of the chord between those two corners. The first and last corner always stay.
    """
    corners = np.asarray(corners, dtype=float)
    if len(corners) < 3 or len(points) < 2:
        return corners
    points = np.ascontiguousarray(points, dtype=float)
    idx = corner_indices(corners, points)
    return corners[_keep_mask(np.ascontiguousarray(corners), points, idx, float(tol))]
