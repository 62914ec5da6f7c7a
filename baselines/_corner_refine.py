"""Sub-sample corner positions: intersect lines fitted to the raw scan points on either side.

ShortStraw puts a corner on a resampled point, so its position is only as good as the resampling
distance and the range noise allow (a few cm). Where both neighbouring pieces of the scan are
straight walls, the intersection of their total-least-squares lines is far more precise.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._corner_thin import corner_indices


@njit(cache=True, nogil=True)
def _fit_line(p: np.ndarray) -> tuple[float, float, float, float, float]:
    """Total-least-squares line through ``(N, 2)`` points: centroid (x, y), unit direction (x, y)
    and RMS residual, from the eigen-decomposition of the 2 × 2 scatter matrix."""
    n = p.shape[0]
    cx, cy = p[:, 0].mean(), p[:, 1].mean()
    sxx = syy = sxy = 0.0
    for i in range(n):
        dx, dy = p[i, 0] - cx, p[i, 1] - cy
        sxx += dx * dx
        syy += dy * dy
        sxy += dx * dy
    half_tr, half_diff = 0.5 * (sxx + syy), 0.5 * (sxx - syy)
    r = math.sqrt(half_diff * half_diff + sxy * sxy)
    small = max(half_tr - r, 0.0)                      # smaller eigenvalue = residual sum of squares
    phi = 0.5 * math.atan2(2.0 * sxy, sxx - syy)       # direction of the larger eigenvector
    return cx, cy, math.cos(phi), math.sin(phi), math.sqrt(small / n)


@njit(cache=True, nogil=True)
def _refine(corners: np.ndarray, points: np.ndarray, idx: np.ndarray, trim: float, min_points: int,
            max_rms: float, min_angle: float, max_move: float) -> np.ndarray:
    k = corners.shape[0]
    out = corners.copy()
    ok = np.zeros(k - 1, dtype=np.bool_)
    lines = np.zeros((k - 1, 4))                       # centroid x, y, direction x, y
    trim2 = trim * trim
    for i in range(k - 1):
        lo, hi = idx[i], idx[i + 1] + 1
        far = np.zeros(hi - lo, dtype=np.bool_)
        for j in range(lo, hi):
            d0x, d0y = points[j, 0] - corners[i, 0], points[j, 1] - corners[i, 1]
            d1x, d1y = points[j, 0] - corners[i + 1, 0], points[j, 1] - corners[i + 1, 1]
            far[j - lo] = d0x * d0x + d0y * d0y > trim2 and d1x * d1x + d1y * d1y > trim2
        if far.sum() < min_points:
            continue
        cx, cy, ux, uy, rms = _fit_line(points[lo:hi][far])
        if rms <= max_rms:
            ok[i] = True
            lines[i, 0], lines[i, 1], lines[i, 2], lines[i, 3] = cx, cy, ux, uy
    sin_min = math.sin(min_angle)
    for i in range(1, k - 1):
        if not (ok[i - 1] and ok[i]):
            continue
        cax, cay, uax, uay = lines[i - 1]
        cbx, cby, ubx, uby = lines[i]
        cross = uax * uby - uay * ubx
        if abs(cross) < sin_min:
            continue
        s = ((cbx - cax) * uby - (cby - cay) * ubx) / cross
        x, y = cax + s * uax, cay + s * uay
        if math.hypot(x - corners[i, 0], y - corners[i, 1]) <= max_move:
            out[i, 0], out[i, 1] = x, y
    return out


def refine_corners(corners: np.ndarray, points: np.ndarray, trim: float = 0.05, min_points: int = 4,
                   max_rms: float = 0.03, min_angle: float = np.radians(30.0),
                   max_move: float = 0.2) -> np.ndarray:
    """Move each interior corner (metres, ``(K, 2)``, in scan order) to the intersection of the lines
    fitted to the raw scan points ``(N, 2)`` (in beam order) before and after it.

    A piece between two consecutive corners gives a line if at least ``min_points`` raw points lie
    more than ``trim`` metres from both its corners and fit a line with RMS ≤ ``max_rms``. A corner
    moves only if both neighbouring pieces give lines meeting at ≥ ``min_angle`` radians and the
    intersection lies within ``max_move`` metres; otherwise (jump edges, field-of-view ends, curved
    pieces) it stays where ShortStraw put it.
    """
    corners = np.ascontiguousarray(corners, dtype=float)
    if len(corners) < 3 or len(points) < min_points:
        return corners.copy()
    points = np.ascontiguousarray(points, dtype=float)
    return _refine(corners, points, corner_indices(corners, points), float(trim), int(min_points), float(max_rms), float(min_angle),
                   float(max_move))
