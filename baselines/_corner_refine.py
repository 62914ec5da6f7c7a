"""Sub-sample corner positions: intersect lines fitted to the raw scan points on either side.

ShortStraw puts a corner on a resampled point, so its position is only as good as the resampling
distance and the range noise allow (a few cm). Where both neighbouring pieces of the scan are
straight walls, the intersection of their total-least-squares lines is far more precise.
"""

from __future__ import annotations

import numpy as np


def _fit_line(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Total-least-squares line through ``(N, 2)`` points: (centroid, unit direction, RMS residual)."""
    c = p.mean(axis=0)
    _, s, vt = np.linalg.svd(p - c, full_matrices=False)
    return c, vt[0], float(s[-1] / np.sqrt(len(p)))


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
    k = len(corners)
    out = np.array(corners, dtype=float, copy=True)
    if k < 3 or len(points) < min_points:
        return out
    d = np.linalg.norm(points[None, :, :] - corners[:, None, :], axis=-1)  # (K, N)
    idx = np.maximum.accumulate(d.argmin(axis=1))
    lines: list[tuple[np.ndarray, np.ndarray] | None] = []
    for i in range(k - 1):
        seg = points[idx[i]: idx[i + 1] + 1]
        far = (np.linalg.norm(seg - corners[i], axis=1) > trim) & (np.linalg.norm(seg - corners[i + 1], axis=1) > trim)
        seg = seg[far]
        if len(seg) < min_points:
            lines.append(None)
            continue
        c, u, rms = _fit_line(seg)
        lines.append((c, u) if rms <= max_rms else None)
    for i in range(1, k - 1):
        a, b = lines[i - 1], lines[i]
        if a is None or b is None:
            continue
        (ca, ua), (cb, ub) = a, b
        cross = ua[0] * ub[1] - ua[1] * ub[0]
        if abs(cross) < np.sin(min_angle):
            continue
        w = cb - ca
        s = (w[0] * ub[1] - w[1] * ub[0]) / cross
        x = ca + s * ua
        if np.linalg.norm(x - corners[i]) <= max_move:
            out[i] = x
    return out
