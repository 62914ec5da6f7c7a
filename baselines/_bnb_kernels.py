"""Compiled kernels of ``bnb-global``: Cartographer's precomputation grids and its depth-first
branch and bound (Hess, Kohler, Rapp, Andor, "Real-Time Loop Closure in 2D LIDAR SLAM",
ICRA 2016, Sec. V; numba, one core).

Conventions (cells of the probability grid, ``resolution`` metres):

* the probability grid is stored as ``uint8`` values ``v`` (probability ``p_min + v/255·(p_max −
  p_min)``, Cartographer's ``PrecomputationGrid2D::ComputeCellValue``);
* ``grids[h]`` (``h = 0 … depth−1``) is level ``h``: cell ``(x, y)`` holds the largest value of the
  ``2^h × 2^h`` window of the probability grid starting at ``(x, y)`` (cells off the grid count 0);
  every level is stored with ``pad = 2^(depth−1) − 1`` cells of margin on each side, so window
  starts left of or below the grid are represented (Cartographer's "wide" grids);
* a candidate is ``(rotation k, x, y, level h)``: the robot at cell ``(x, y)`` with heading
  ``thetas[k]`` standing for the ``2^h × 2^h`` block of translations ``[x, x+2^h) × [y, y+2^h)``;
  its score is the mean of ``grids[h]`` at the scan's cells ``(x, y) + offsets[k, i]``, an upper
  bound of every translation in the block (Eq. (14)–(15) of the paper), exact at ``h = 0``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


def pyramid(base: np.ndarray, depth: int) -> np.ndarray:
    """The precomputation grids ``(depth, H + 2·pad, W + 2·pad)`` uint8 of a ``(H, W)`` uint8
    probability grid: level ``h`` is the max over the ``2^h``-wide window starting at each cell,
    built by doubling (``M_2w(x) = max(M_w(x), M_w(x + w))`` along each axis), which is exact."""
    pad = (1 << (depth - 1)) - 1
    h0, w0 = base.shape
    out = np.zeros((depth, h0 + 2 * pad, w0 + 2 * pad), dtype=np.uint8)
    out[0, pad:pad + h0, pad:pad + w0] = base
    for h in range(1, depth):
        half = 1 << (h - 1)
        prev = out[h - 1]
        cur = prev.copy()
        np.maximum(cur[:, :-half], prev[:, half:], out=cur[:, :-half])
        row = cur.copy()
        np.maximum(row[:-half, :], cur[half:, :], out=row[:-half, :])
        out[h] = row
    return out


def discretize(points: np.ndarray, thetas: np.ndarray, resolution: float) -> np.ndarray:
    """Cell offsets ``(R, N, 2)`` int32 (column, row) of scan ``points`` ``(N, 2)`` (metres,
    sensor frame) rotated by each of ``thetas`` ``(R,)``, for a robot at a cell centre
    (Cartographer's ``GenerateRotatedScans`` + ``DiscretizeScans``)."""
    c, s = np.cos(thetas)[:, None], np.sin(thetas)[:, None]
    x = c * points[None, :, 0] - s * points[None, :, 1]
    y = s * points[None, :, 0] + c * points[None, :, 1]
    return np.ascontiguousarray(np.stack((np.rint(x / resolution), np.rint(y / resolution)), axis=-1)
                                .astype(np.int32))


@njit(cache=True, nogil=True)
def candidate_sum(grids: np.ndarray, pad: int, offsets: np.ndarray, k: int, x: int, y: int,
                  h: int) -> int:
    """Sum of level ``h``'s values at the scan cells of candidate ``(k, x, y)`` (0 off the grid)."""
    hp, wp = grids.shape[1], grids.shape[2]
    total = 0
    for i in range(offsets.shape[1]):
        qx = x + offsets[k, i, 0] + pad
        qy = y + offsets[k, i, 1] + pad
        if 0 <= qx < wp and 0 <= qy < hp:
            total += grids[h, qy, qx]
    return total


@njit(cache=True, nogil=True)
def _distinct(k1: int, x1: int, y1: int, k2: int, x2: int, y2: int, n_rot: int,
              dist_cells: float, rot_steps: int) -> bool:
    dk = abs(k1 - k2)
    dk = min(dk, n_rot - dk)
    dx, dy = x1 - x2, y1 - y2
    return dx * dx + dy * dy > dist_cells * dist_cells or dk > rot_steps


@njit(cache=True, nogil=True)
def _insert(hk, hx, hy, hs, count, k, x, y, s, n_rot, dist_cells, rot_steps):
    """Insert leaf ``(k, x, y)`` with sum ``s`` into the ranked list of distinct hypotheses (best
    first): rejected if a better one lies within the distinctness radius, else it replaces every
    worse one within it. Returns the new count."""
    cap = hk.shape[0]
    for j in range(count):
        if not _distinct(k, x, y, hk[j], hx[j], hy[j], n_rot, dist_cells, rot_steps) and hs[j] >= s:
            return count
    m = 0
    for j in range(count):  # drop the worse ones nearby
        if _distinct(k, x, y, hk[j], hx[j], hy[j], n_rot, dist_cells, rot_steps):
            hk[m], hx[m], hy[m], hs[m] = hk[j], hx[j], hy[j], hs[j]
            m += 1
    count = m
    pos = count
    while pos > 0 and hs[pos - 1] < s:
        pos -= 1
    if pos >= cap:
        return count
    last = min(count, cap - 1)
    for j in range(last, pos, -1):
        hk[j], hx[j], hy[j], hs[j] = hk[j - 1], hx[j - 1], hy[j - 1], hs[j - 1]
    hk[pos], hx[pos], hy[pos], hs[pos] = k, x, y, s
    return min(count + 1, cap)


@njit(cache=True, nogil=True)
def _candidates(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Room for ``n`` candidates: rotation index, x and y (cells), score (sum of cell values)."""
    return (np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64),
            np.empty(n, dtype=np.float64))


@njit(cache=True, nogil=True)
def branch_and_bound(grids: np.ndarray, pad: int, offsets: np.ndarray, x_min: int, x_max: int,
                     y_min: int, y_max: int, min_sum: float, n_best: int, dist_cells: float,
                     rot_steps: int):
    """Depth-first branch and bound over rotations × translations ``[x_min, x_max] × [y_min,
    y_max]`` (cells), Cartographer's ``ComputeLowestResolutionCandidates`` + ``BranchAndBound``:
    the coarsest level's candidates are scored and taken best first; a node whose bound does not
    exceed the current threshold is cut (its siblings after it are worse); otherwise its (up to)
    four children on the next finer level are scored and searched, best first. The threshold
    is ``min_sum`` (the score threshold, as a sum of cell values over the scan's points) until
    ``n_best`` distinct leaves are held, then the ``n_best``-th best leaf's sum (with ``n_best``
    = 1 this is Cartographer's search exactly).

    Returns ``(k, x, y, sums, count, scored)``: the ranked hypotheses (rotation index, cells,
    sum of values; the first ``count`` are valid) and how many candidates were scored.
    """
    depth = grids.shape[0]
    n_rot = offsets.shape[0]
    top = 1 << (depth - 1)
    nx = (x_max - x_min + top) // top
    ny = (y_max - y_min + top) // top
    n_top = n_rot * nx * ny
    # the coarsest level, scored and sorted (ascending: pushed so the best is popped first)
    ck, cx, cy, cs = _candidates(n_top)
    n = 0
    for k in range(n_rot):
        for ix in range(nx):
            for iy in range(ny):
                x, y = x_min + ix * top, y_min + iy * top
                ck[n], cx[n], cy[n] = k, x, y
                cs[n] = candidate_sum(grids, pad, offsets, k, x, y, depth - 1)
                n += 1
    scored = n_top
    order = np.argsort(cs, kind="mergesort")
    cap = n_top + 4 * depth + 4
    sk = np.empty(cap, dtype=np.int64)
    sx = np.empty(cap, dtype=np.int64)
    sy = np.empty(cap, dtype=np.int64)
    sh = np.empty(cap, dtype=np.int64)
    ss = np.empty(cap, dtype=np.float64)
    sp = 0
    for j in range(n_top):
        o = order[j]
        if cs[o] > min_sum:
            sk[sp], sx[sp], sy[sp], sh[sp], ss[sp] = ck[o], cx[o], cy[o], depth - 1, cs[o]
            sp += 1
    hk = np.zeros(n_best, dtype=np.int64)
    hx = np.zeros(n_best, dtype=np.int64)
    hy = np.zeros(n_best, dtype=np.int64)
    hs = np.zeros(n_best, dtype=np.float64)
    count = 0
    child_k, child_x, child_y, child_s = _candidates(4)
    while sp > 0:
        sp -= 1
        k, x, y, h, s = sk[sp], sx[sp], sy[sp], sh[sp], ss[sp]
        thr = min_sum if count < n_best else max(min_sum, hs[n_best - 1])
        if s <= thr:
            continue
        if h == 0:
            count = _insert(hk, hx, hy, hs, count, k, x, y, s, n_rot, dist_cells, rot_steps)
            continue
        half = 1 << (h - 1)
        m = 0
        for ox in (0, half):
            if x + ox > x_max:
                break
            for oy in (0, half):
                if y + oy > y_max:
                    break
                child_k[m], child_x[m], child_y[m] = k, x + ox, y + oy
                child_s[m] = candidate_sum(grids, pad, offsets, k, x + ox, y + oy, h - 1)
                m += 1
        scored += m
        # push in ascending order of score: the best child is searched first
        for a in range(1, m):
            b = a
            while b > 0 and child_s[b - 1] > child_s[b]:
                child_k[b - 1], child_k[b] = child_k[b], child_k[b - 1]
                child_x[b - 1], child_x[b] = child_x[b], child_x[b - 1]
                child_y[b - 1], child_y[b] = child_y[b], child_y[b - 1]
                child_s[b - 1], child_s[b] = child_s[b], child_s[b - 1]
                b -= 1
        for a in range(m):
            if child_s[a] > thr:
                sk[sp], sx[sp], sy[sp], sh[sp], ss[sp] = child_k[a], child_x[a], child_y[a], h - 1, child_s[a]
                sp += 1
    return hk, hx, hy, hs, count, scored


@njit(cache=True, nogil=True)
def exhaustive(grids: np.ndarray, pad: int, offsets: np.ndarray, x_min: int, x_max: int,
               y_min: int, y_max: int) -> tuple[int, int, int, int]:
    """The best leaf by brute force (level 0 at every rotation and translation): ``(k, x, y,
    sum)``; the reference the tests hold the branch and bound to."""
    best, bk, bx, by = -1, 0, 0, 0
    for k in range(offsets.shape[0]):
        for x in range(x_min, x_max + 1):
            for y in range(y_min, y_max + 1):
                s = candidate_sum(grids, pad, offsets, k, x, y, 0)
                if s > best:
                    best, bk, bx, by = s, k, x, y
    return bk, bx, by, best


def angular_step(max_range_m: float, resolution: float) -> float:
    """Cartographer's angular step (radians) for a scan reaching ``max_range_m`` metres: the
    rotation that moves the farthest point by at most one cell (paper Eq. (7)), with its
    safety margin ``1 − 10⁻³`` and the range floored at three cells."""
    d = max(max_range_m, 3.0 * resolution)
    return (1.0 - 1e-3) * math.acos(1.0 - resolution ** 2 / (2.0 * d ** 2))
