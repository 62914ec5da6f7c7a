"""Compiled kernels behind ``tf-plus`` (numba, one core): grid scoring and point-to-line pairs.

Same arithmetic as a numpy version, without its (K, M, W, 2) temporaries, which dominated
the matcher's time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def grid_scores_kernel(table: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       points: np.ndarray, positions: np.ndarray,
                       headings: np.ndarray) -> np.ndarray:
    """Mean distance-field value ``(N, H)`` of ``points`` ``(M, 2)`` at every position × heading
    (indices clipped into the table, whose border holds the truncation value)."""
    ny, nx = table.shape
    n, h, m = positions.shape[0], headings.shape[0], points.shape[0]
    out = np.empty((n, h))
    rx = np.empty((h, m))
    ry = np.empty((h, m))
    for j in range(h):
        c, s = math.cos(headings[j]), math.sin(headings[j])
        for i in range(m):
            rx[j, i] = c * points[i, 0] - s * points[i, 1]
            ry[j, i] = s * points[i, 0] + c * points[i, 1]
    inv = 1.0 / resolution
    for p in range(n):
        px, py = positions[p, 0] - origin_x, positions[p, 1] - origin_y
        for j in range(h):
            acc = 0.0
            for i in range(m):
                ix = int(math.floor((px + rx[j, i]) * inv))
                iy = int(math.floor((py + ry[j, i]) * inv))
                ix = min(max(ix, 0), nx - 1)
                iy = min(max(iy, 0), ny - 1)
                acc += table[iy, ix]
            out[p, j] = acc / m
    return out


@njit(cache=True, nogil=True)
def pairs_kernel(points: np.ndarray, delta: np.ndarray, q: np.ndarray, normal: np.ndarray,
                 angle_min: float, resolution: float, window: int, gate: float,
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Point-to-line pairs of each candidate and one Gauss–Newton system.

    ``points`` ``(M, 2)`` real points (sensor frame), ``delta`` ``(K, 3)`` current corrections
    ``(tx, ty, φ)``, ``q``/``normal`` ``(K, n, 2)`` virtual points/unit normals (NaN: none).
    Each transformed point ``R(φ) p + t`` is paired with the nearest virtual point within
    ``window`` beams of its bearing if closer than ``gate`` (metres). Returns the normal
    equations ``H`` ``(K, 3, 3)``, ``g`` ``(K, 3)`` and the signed residuals ``(K, M)`` (NaN:
    unpaired).
    """
    k_n, m = delta.shape[0], points.shape[0]
    n = q.shape[1]
    hh = np.zeros((k_n, 3, 3))
    gg = np.zeros((k_n, 3))
    res = np.full((k_n, m), np.nan)
    for k in range(k_n):
        c, s = math.cos(delta[k, 2]), math.sin(delta[k, 2])
        for i in range(m):
            rx = c * points[i, 0] - s * points[i, 1]
            ry = s * points[i, 0] + c * points[i, 1]
            x, y = rx + delta[k, 0], ry + delta[k, 1]
            j0 = int(round((math.atan2(y, x) - angle_min) / resolution))
            best, bj = gate * gate, -1
            for j in range(max(j0 - window, 0), min(j0 + window + 1, n)):
                qx = q[k, j, 0]
                if math.isnan(qx) or math.isnan(normal[k, j, 0]):
                    continue
                d2 = (x - qx) ** 2 + (y - q[k, j, 1]) ** 2
                if d2 < best:
                    best, bj = d2, j
            if bj < 0:
                continue
            nx, ny = normal[k, bj, 0], normal[k, bj, 1]
            r = nx * (x - q[k, bj, 0]) + ny * (y - q[k, bj, 1])
            res[k, i] = r
            jac = (nx, ny, -nx * ry + ny * rx)
            for a in range(3):
                gg[k, a] += jac[a] * r
                for b in range(3):
                    hh[k, a, b] += jac[a] * jac[b]
    return hh, gg, res
