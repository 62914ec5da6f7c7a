"""Numba kernels of ``cv-corners``' hypothesis search (:mod:`tfloc.baselines._corner_match`).

Loops written out, so that no array grows with the number of candidate pairs (10⁶ on real scans
before the rotation/shift window is applied); one-to-one inliers are counted with a uniform grid
over the virtual corners (cells of the inlier tolerance) instead of a k-d tree per hypothesis.
Metres and radians throughout.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _agreeing(lb_sorted: np.ndarray, length: float, length_tol: float) -> tuple[int, int]:
    """The pairs ``[lo, hi)`` of b (``lb_sorted``: lengths ascending) whose length agrees with
    ``length`` within ``length_tol``."""
    lo = np.searchsorted(lb_sorted, length - length_tol, side="left")
    hi = np.searchsorted(lb_sorted, length + length_tol, side="right")
    return lo, hi


@njit(cache=True, nogil=True)
def _pair_transform(anga: np.ndarray, ma: np.ndarray, p: int, angb: np.ndarray, mb: np.ndarray,
                    q: int, max_angle: float, shift2: float) -> tuple[bool, float, float, float, float, float]:
    """The rigid transform mapping pair ``p`` of a onto pair ``q`` of b (see
    :func:`pair_transforms`): whether it lies outside the window (``|theta| > max_angle`` or
    ``‖t‖² > shift2``), ``theta`` (wrapped), its cosine and sine, and ``t``."""
    d = angb[q] - anga[p]
    d = (d + math.pi) % (2.0 * math.pi) - math.pi
    if abs(d) > max_angle:
        return True, d, 0.0, 0.0, 0.0, 0.0
    c, s = math.cos(d), math.sin(d)
    tx = mb[q, 0] - (c * ma[p, 0] - s * ma[p, 1])
    ty = mb[q, 1] - (s * ma[p, 0] + c * ma[p, 1])
    return tx * tx + ty * ty > shift2, d, c, s, tx, ty


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
        lo, hi = _agreeing(lb_sorted, la[p], length_tol)
        for q in range(lo, hi):
            outside, d, _, _, tx, ty = _pair_transform(anga, ma, p, angb, mb, q, max_angle, shift2)
            if outside:
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
def _grid(b: np.ndarray, tol: float) -> tuple[float, float, float, int, int, np.ndarray, np.ndarray]:
    """A uniform grid over the corners ``b`` with cells at least ``tol`` metres wide (so that all
    corners within ``tol`` of a point lie in its 3 × 3 block of cells); at most ~4·10⁶ cells.
    Returns origin, cell size, shape, cell start offsets ``(nx·ny + 1,)`` and the corner indices
    sorted by cell (ascending within a cell)."""
    m = b.shape[0]
    x0, y0 = b[:, 0].min(), b[:, 1].min()
    w, h = b[:, 0].max() - x0, b[:, 1].max() - y0
    cell = max(tol, math.sqrt(w * h / 4.0e6), 1e-9)
    nx, ny = int(w / cell) + 1, int(h / cell) + 1
    key = np.empty(m, dtype=np.int64)
    start = np.zeros(nx * ny + 1, dtype=np.int64)
    for k in range(m):
        key[k] = int((b[k, 0] - x0) / cell) * ny + int((b[k, 1] - y0) / cell)
        start[key[k] + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    items = np.empty(m, dtype=np.int64)
    for k in range(m):
        items[fill[key[k]]] = k
        fill[key[k]] += 1
    return x0, y0, cell, nx, ny, start, items


@njit(cache=True, nogil=True)
def _score(c: float, s: float, tx: float, ty: float, a: np.ndarray, b: np.ndarray, tol2: float,
           grid: tuple[float, float, float, int, int, np.ndarray, np.ndarray],
           nn_b: np.ndarray, d_b: np.ndarray, nn_a: np.ndarray, d_a: np.ndarray) -> tuple[int, float]:
    """One-to-one inliers of ``R a + t`` against ``b``: pairs (i, k) within ``√tol2`` metres where
    k is i's nearest corner and i is k's nearest (ties go to the lower index). Only corners within
    the tolerance can form such a pair, so each moved corner looks in its 3 × 3 block of ``grid``
    cells (:func:`_grid`) only. Returns their number and summed distance; leaves i's partner
    (−1 = none) in ``nn_b`` and the squared distance in ``d_b``."""
    x0, y0, cell, nx, ny, start, items = grid
    n, m = a.shape[0], b.shape[0]
    for k in range(m):
        d_a[k] = np.inf
        nn_a[k] = -1
    for i in range(n):
        x = c * a[i, 0] - s * a[i, 1] + tx
        y = s * a[i, 0] + c * a[i, 1] + ty
        best, arg = np.inf, -1
        fx, fy = (x - x0) / cell, (y - y0) / cell
        if -1.0 <= fx < nx + 1.0 and -1.0 <= fy < ny + 1.0:  # else no cell within reach
            cx, cy = int(math.floor(fx)), int(math.floor(fy))
            for gx in range(max(cx - 1, 0), min(cx + 2, nx)):
                for gy in range(max(cy - 1, 0), min(cy + 2, ny)):
                    g = gx * ny + gy
                    for j in range(start[g], start[g + 1]):
                        k = items[j]
                        dx, dy = x - b[k, 0], y - b[k, 1]
                        d2 = dx * dx + dy * dy
                        if d2 > tol2:
                            continue
                        if d2 < best or (d2 == best and k < arg):
                            best, arg = d2, k
                        if d2 < d_a[k]:        # i ascends: on a tie the lower i stays
                            d_a[k], nn_a[k] = d2, i
        nn_b[i], d_b[i] = arg, best
    count, resid = 0, 0.0
    for i in range(n):
        if nn_b[i] >= 0 and nn_a[nn_b[i]] == i:
            count += 1
            resid += math.sqrt(d_b[i])
        else:
            nn_b[i] = -1
    return count, resid


@njit(cache=True, nogil=True)
def inlier_counts(theta: np.ndarray, t: np.ndarray, a: np.ndarray, b: np.ndarray,
                  tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Per hypothesis ``b ≈ R(theta[h]) a + t[h]``: the number of one-to-one inliers (i is k's
    nearest, k is i's nearest, within ``tol`` metres) and their summed distance (metres)."""
    n_h, n, m = theta.shape[0], a.shape[0], b.shape[0]
    count = np.zeros(n_h, dtype=np.int64)
    resid = np.zeros(n_h)
    nn_b, d_b = np.empty(n, dtype=np.int64), np.empty(n)
    nn_a, d_a = np.empty(m, dtype=np.int64), np.empty(m)
    grid = _grid(b, tol)
    for h in range(n_h):
        count[h], resid[h] = _score(math.cos(theta[h]), math.sin(theta[h]), t[h, 0], t[h, 1], a, b,
                                    tol * tol, grid, nn_b, d_b, nn_a, d_a)
    return count, resid


@njit(cache=True, nogil=True)
def _supporting_pairs(a: np.ndarray, b: np.ndarray, partner: np.ndarray, min_length: float,
                      length_tol: float) -> int:
    """How many pairs of a's inliers (``partner`` ≥ 0) are at least ``min_length`` long and agree in
    length with their partners' pair within ``length_tol``: the pairs that propose this match."""
    idx = np.flatnonzero(partner >= 0)
    n = 0
    for u in range(idx.size):
        i = idx[u]
        for v in range(u + 1, idx.size):
            j = idx[v]
            la = math.hypot(a[j, 0] - a[i, 0], a[j, 1] - a[i, 1])
            lb = math.hypot(b[partner[j], 0] - b[partner[i], 0], b[partner[j], 1] - b[partner[i], 1])
            if la >= min_length and abs(la - lb) <= length_tol:
                n += 1
    return n


@njit(cache=True, nogil=True)
def adaptive_search(a: np.ndarray, b: np.ndarray, la: np.ndarray, anga: np.ndarray, ma: np.ndarray,
                    draw_order: np.ndarray, lb_sorted: np.ndarray, angb: np.ndarray, mb: np.ndarray,
                    min_length: float, length_tol: float, max_angle: float, max_shift: float, tol: float,
                    confidence: float, max_hypotheses: int) -> tuple[float, float, float, int, int, int]:
    """Pairs of a (lengths ``la``, directions ``anga``, midpoints ``ma``) drawn in ``draw_order``;
    each is matched with every pair of b of agreeing length (``lb_sorted`` ascending, ``angb``,
    ``mb``), and each transform inside the window is scored at once by its one-to-one inliers
    (ties: smaller summed distance, then the earlier).

    Stops after all pairs, after ``max_hypotheses`` scored transforms, or, as adaptive RANSAC,
    once the draws made would have drawn a supporting pair of the best match so far with
    probability ``confidence``: with w = (its supporting pairs) / (all pairs of a), after
    n ≥ log(1 − confidence) / log(1 − w) draws.

    Returns the best ``theta, tx, ty`` (radians, metres), its inlier count, the number of scored
    transforms and of drawn pairs.
    """
    n_pairs, n, m = la.shape[0], a.shape[0], b.shape[0]
    nn_b, d_b = np.empty(n, dtype=np.int64), np.empty(n)
    nn_a, d_a = np.empty(m, dtype=np.int64), np.empty(m)
    grid = _grid(b, tol)
    best = (0.0, 0.0, 0.0)
    best_count, best_resid = -1, np.inf
    need = n_pairs
    log_miss = math.log(1.0 - confidence) if confidence < 1.0 else -np.inf
    scored, drawn, support = 0, 0, 0
    shift2 = max_shift * max_shift
    for p in draw_order:
        if drawn >= need or scored >= max_hypotheses:
            break
        drawn += 1
        lo, hi = _agreeing(lb_sorted, la[p], length_tol)
        improved = False
        for q in range(lo, hi):
            outside, d, c, s, tx, ty = _pair_transform(anga, ma, p, angb, mb, q, max_angle, shift2)
            if outside:
                continue
            if scored >= max_hypotheses:
                break
            scored += 1
            count, resid = _score(c, s, tx, ty, a, b, tol * tol, grid, nn_b, d_b, nn_a, d_a)
            if count > best_count or (count == best_count and resid < best_resid):
                best, best_count, best_resid = (d, tx, ty), count, resid
                improved = True
                support = _supporting_pairs(a, b, nn_b, min_length, length_tol)
        if improved and log_miss > -np.inf:
            w = support / n_pairs
            if w >= 1.0:
                need = drawn
            elif w > 0.0:
                need = min(n_pairs, int(math.ceil(log_miss / math.log(1.0 - w))))
    return best[0], best[1], best[2], best_count, scored, drawn
