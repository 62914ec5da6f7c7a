"""Compiled ray–segment kernel behind :meth:`VectorMap.raycast` (numba, one core)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, fastmath=False, nogil=True)
def raycast_segments(poses: np.ndarray, rel_angles: np.ndarray, segs: np.ndarray,
                     max_range: float) -> np.ndarray:
    """Ranges from each pose ``(P, 3)`` along each beam ``(B,)`` to the nearest of ``segs``
    ``(M, 4)`` = (ax, ay, bx, by). No hit before ``max_range`` gives ``inf``. Metres, radians.

    Segments farther than ``max_range`` from a pose are culled first, so the cost is
    O(P·(M + B·M_near)).
    """
    P = poses.shape[0]
    B = rel_angles.shape[0]
    M = segs.shape[0]
    out = np.full((P, B), np.inf)
    near = np.empty(M, dtype=np.int64)
    for p in range(P):
        ox, oy, th = poses[p, 0], poses[p, 1], poses[p, 2]
        k = 0
        for m in range(M):
            ax, ay = segs[m, 0] - ox, segs[m, 1] - oy
            ex, ey = segs[m, 2] - segs[m, 0], segs[m, 3] - segs[m, 1]
            ll = ex * ex + ey * ey
            u = 0.0
            if ll > 0.0:
                u = -(ax * ex + ay * ey) / ll
                u = min(1.0, max(0.0, u))
            cx, cy = ax + u * ex, ay + u * ey
            if cx * cx + cy * cy < max_range * max_range:
                near[k] = m
                k += 1
        for b in range(B):
            a = th + rel_angles[b]
            dx, dy = np.cos(a), np.sin(a)
            best = max_range
            for j in range(k):
                m = near[j]
                wx, wy = segs[m, 0] - ox, segs[m, 1] - oy
                ex, ey = segs[m, 2] - segs[m, 0], segs[m, 3] - segs[m, 1]
                den = dx * ey - dy * ex
                if abs(den) < 1e-12:
                    continue
                t = (wx * ey - wy * ex) / den
                if t < 0.0 or t >= best:
                    continue
                u = (wx * dy - wy * dx) / den
                if -1e-9 <= u <= 1.0 + 1e-9:
                    best = t
            if best < max_range:
                out[p, b] = best
    return out
