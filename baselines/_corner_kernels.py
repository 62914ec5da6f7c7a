"""Numba kernels of ``cv-corners``' hypothesis search (:mod:`baselines._corner_match`).

Both loops are the vectorised numpy code they replace written out, so that no array grows with
the number of candidate pairs (10⁶ on real scans before the rotation/shift window is applied) and
no k-d tree is built per call. Metres and radians throughout.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def pair_transforms(la: np.ndarray, anga: np.ndarray, ma: np.ndarray,
                    lb_sorted: np.ndarray, angb: np.ndarray, mb: np.ndarray,
                    length_tol: float, max_angle: float, max_shift: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rigid transforms mapping corner pair p of set a onto pair q of set b.

    ``la, anga, ma``: length, direction (radians) and midpoint ``(P, 2)`` of a's pairs;
    ``lb_sorted, angb, mb``: the same for b's pairs, sorted by length. A pair of pairs gives
    ``theta = angb − anga`` (wrapped) and ``t = mb − R(theta) ma`` when the lengths agree within
    ``length_tol``, ``|theta| ≤ max_angle`` and ``‖t‖ ≤ max_shift``.
    Returns ``theta (H,)``, ``t (H, 2)`` and the a-pair index of each ``(H,)``, in a-pair order,
    then b's length order.
    """
    pa = la.shape[0]
    cap = 1024
    theta = np.empty(cap)
    t = np.empty((cap, 2))
    src = np.empty(cap, dtype=np.int64)
    h = 0
    shift2 = max_shift * max_shift
    for p in range(pa):
        lo = np.searchsorted(lb_sorted, la[p] - length_tol, side="left")
        hi = np.searchsorted(lb_sorted, la[p] + length_tol, side="right")
        for q in range(lo, hi):
            d = angb[q] - anga[p]
            d = (d + math.pi) % (2.0 * math.pi) - math.pi
            if abs(d) > max_angle:
                continue
            c, s = math.cos(d), math.sin(d)
            tx = mb[q, 0] - (c * ma[p, 0] - s * ma[p, 1])
            ty = mb[q, 1] - (s * ma[p, 0] + c * ma[p, 1])
            if tx * tx + ty * ty > shift2:
                continue
            if h == cap:
                cap *= 2
                theta2, t2, src2 = np.empty(cap), np.empty((cap, 2)), np.empty(cap, dtype=np.int64)
                theta2[:h], t2[:h], src2[:h] = theta, t, src
                theta, t, src = theta2, t2, src2
            theta[h], t[h, 0], t[h, 1], src[h] = d, tx, ty, p
            h += 1
    return theta[:h].copy(), t[:h].copy(), src[:h].copy()


@njit(cache=True, nogil=True)
def inlier_counts(theta: np.ndarray, t: np.ndarray, a: np.ndarray, b: np.ndarray,
                  tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Per hypothesis ``b ≈ R(theta[h]) a + t[h]``: the number of one-to-one inliers (i is k's
    nearest, k is i's nearest, within ``tol`` metres) and their summed distance (metres).

    Brute force over the ``N × M`` distances of each hypothesis (one pass gives both nearest
    neighbours); ties go to the lower index.
    """
    n_h, n, m = theta.shape[0], a.shape[0], b.shape[0]
    count = np.zeros(n_h, dtype=np.int64)
    resid = np.zeros(n_h)
    nn_b = np.empty(n, dtype=np.int64)
    d_b = np.empty(n)
    nn_a = np.empty(m, dtype=np.int64)
    d_a = np.empty(m)
    tol2 = tol * tol
    for h in range(n_h):
        c, s = math.cos(theta[h]), math.sin(theta[h])
        for k in range(m):
            d_a[k] = np.inf
            nn_a[k] = -1
        for i in range(n):
            x = c * a[i, 0] - s * a[i, 1] + t[h, 0]
            y = s * a[i, 0] + c * a[i, 1] + t[h, 1]
            best, arg = np.inf, -1
            for k in range(m):
                dx, dy = x - b[k, 0], y - b[k, 1]
                d2 = dx * dx + dy * dy
                if d2 < best:
                    best, arg = d2, k
                if d2 < d_a[k]:
                    d_a[k], nn_a[k] = d2, i
            nn_b[i], d_b[i] = arg, best
        for i in range(n):
            if d_b[i] <= tol2 and nn_a[nn_b[i]] == i:
                count[h] += 1
                resid[h] += math.sqrt(d_b[i])
    return count, resid
