"""Compiled kernels of ``tf-plus``'s coarse search (:mod:`tfloc.tfplus.coarse`; numba, one core).

The lattice's free positions, the mean distance-field score of every position × heading, the
shortlist of the lowest scores, their rescoring on all points and their thinning to candidates
some distance apart. Same arithmetic as a numpy version, without its (K, M, W, 2) temporaries,
which dominated the matcher's time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tfloc.maps.inside import raster_code

_EDGE = 1e-6  # cells: a lattice look-up this close to a cell edge is made the plain way


@njit(cache=True, nogil=True)
def _clear_points(centre_x: float, centre_y: float, offsets: np.ndarray, table: np.ndarray,
                  corner_x: float, corner_y: float, resolution: float,
                  clearance: float) -> np.ndarray:
    """The points ``centre + offsets`` ``(N, 2)`` (metres), in order, where the distance field
    (``table``, cells of ``resolution`` from the corner, indices clipped into it) is at least
    ``clearance`` (of the table's dtype): ``(K, 2)``."""
    h, w = table.shape
    flat = table.ravel()
    out = np.empty((offsets.shape[0], 2))
    k = 0
    for i in range(offsets.shape[0]):
        x, y = centre_x + offsets[i, 0], centre_y + offsets[i, 1]
        ix = min(max(np.int64(math.floor((x - corner_x) / resolution)), 0), w - 1)
        iy = min(max(np.int64(math.floor((y - corner_y) / resolution)), 0), h - 1)
        if flat[iy * w + ix] >= clearance:
            out[k, 0], out[k, 1] = x, y
            k += 1
    return out[:k]


@njit(cache=True, nogil=True)
def lattice_kernel(centre_x: float, centre_y: float, offsets: np.ndarray, table: np.ndarray,
                   corner_x: float, corner_y: float, resolution: float, clearance: float,
                   area: tuple, free: tuple, sure: float) -> tuple[np.ndarray, bool]:
    """:func:`tfloc.tfplus.coarse.lattice`'s positions on a vector map, in one call: of the
    points clear of the map (:func:`_clear_points`), in order, those in the mapped area and in
    free space (:func:`tfloc.maps.inside.raster_code` on the area's and the free space's rings,
    ``Rings.kernel``). Returns them ``(K, 2)`` and whether every point was decided (False: one
    lay too near a boundary for the compiled test; ask the map)."""
    clear = _clear_points(centre_x, centre_y, offsets, table, corner_x, corner_y, resolution,
                          clearance)
    keep = np.zeros(clear.shape[0], dtype=np.bool_)
    for i in range(clear.shape[0]):
        code = raster_code(clear[i, 0], clear[i, 1], area, sure)
        if code == 1:
            code = raster_code(clear[i, 0], clear[i, 1], free, sure)
        if code < 0:
            return np.empty((0, 2)), False
        keep[i] = code == 1
    return clear[keep], True


@njit(cache=True, nogil=True)
def grid_lattice_kernel(centre_x: float, centre_y: float, offsets: np.ndarray, table: np.ndarray,
                        corner_x: float, corner_y: float, resolution: float, clearance: float,
                        origin_x: float, origin_y: float, cell: float, free: np.ndarray,
                        distance: np.ndarray, min_distance: float) -> np.ndarray:
    """:func:`tfloc.tfplus.coarse.lattice`'s positions on a grid map, in one call: of the points
    clear of the map (:func:`_clear_points`), in order, those that lie in a known free cell of
    the grid (cells of ``cell`` metres from ``origin``; ``free`` ``(H, W)``) whose centre is at
    least ``min_distance`` from every occupied cell's (``distance``): the tests of
    :meth:`tfloc.maps.grid.GridMap.in_bounds` and ``is_free``, element by element."""
    clear = _clear_points(centre_x, centre_y, offsets, table, corner_x, corner_y, resolution,
                          clearance)
    gh, gw = free.shape
    keep = np.zeros(clear.shape[0], dtype=np.bool_)
    for n in range(clear.shape[0]):
        i = np.int64(math.floor((clear[n, 0] - origin_x) / cell))
        j = np.int64(math.floor((clear[n, 1] - origin_y) / cell))
        if 0 <= i < gw and 0 <= j < gh and free[j, i] and distance[j, i] >= min_distance:
            keep[n] = True
    return clear[keep]


@njit(cache=True, nogil=True)
def _lattice_offsets(positions: np.ndarray, step: float, inv: float,
                     nx: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """For positions on a square lattice of spacing ``step`` metres, a whole number ``w`` of
    table cells (``1 / inv`` metres, ``nx`` columns): each one's lattice offset ``(kx, ky)`` from
    ``positions[0]`` and its flat table offset ``w·(ky·nx + kx)``; ``w`` = 0 when the positions
    are on no such lattice."""
    n = positions.shape[0]
    kx = np.zeros(n, dtype=np.int64)
    ky = np.zeros(n, dtype=np.int64)
    flat = np.zeros(n, dtype=np.int64)
    cells = step * inv
    w = np.int64(round(cells)) if step > 0.0 else np.int64(0)
    if n == 0 or w < 1:
        return kx, ky, flat, 0
    worst = 0.0
    for p in range(n):
        fx = (positions[p, 0] - positions[0, 0]) / step
        fy = (positions[p, 1] - positions[0, 1]) / step
        kx[p], ky[p] = np.int64(round(fx)), np.int64(round(fy))
        if abs(fx - kx[p]) > 1e-6 or abs(fy - ky[p]) > 1e-6:
            return kx, ky, flat, 0
        worst = max(worst, abs(float(kx[p])), abs(float(ky[p])))
        flat[p] = w * (ky[p] * nx + kx[p])
    if abs(cells - w) * (worst + 1.0) > 1e-8:     # the lattice drifts off the cells
        return kx, ky, flat, 0
    return kx, ky, flat, w


@njit(cache=True, nogil=True)
def grid_scores_kernel(table: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       points: np.ndarray, positions: np.ndarray, headings: np.ndarray,
                       step: float = 0.0) -> np.ndarray:
    """Mean distance-field value ``(N, H)`` of ``points`` ``(M, 2)`` at every position × heading
    (indices clipped into the table, whose border holds the truncation value).

    Per heading and point, the cell indices of all positions are computed first (a loop the
    compiler vectorises), then their table values are added; each sum runs over the points in
    order, so the scores are those of the plain triple loop, bit for bit.

    Positions on a lattice of ``step`` metres that is a whole number ``w`` of cells (the coarse
    search's; 0: no lattice) need no cell index each: for one heading and point, position ``p``
    at lattice offset ``(kx, ky)`` from ``positions[0]`` falls in cell ``(ix₀ + w·kx,
    iy₀ + w·ky)``, ``(ix₀, iy₀)`` the cell of ``positions[0]``'s point. That holds exactly when
    that point lies more than ``_EDGE`` cells from a cell edge (the plain formula's rounding is
    ~1e-11 cells) and no index needs clipping; elsewhere the indices are computed as above."""
    ny, nx = table.shape
    n, h, m = positions.shape[0], headings.shape[0], points.shape[0]
    qx = np.empty((h, m))
    qy = np.empty((h, m))
    for j in range(h):
        c, s = math.cos(headings[j]), math.sin(headings[j])
        for i in range(m):
            qx[j, i] = (c * points[i, 0] - s * points[i, 1]) - origin_x
            qy[j, i] = (s * points[i, 0] + c * points[i, 1]) - origin_y
    inv = 1.0 / resolution
    px = np.ascontiguousarray(positions[:, 0])
    py = np.ascontiguousarray(positions[:, 1])
    flat = table.ravel()
    kx, ky, offset, w = _lattice_offsets(positions, step, inv, nx)
    if w > 0:
        kx_lo, kx_hi, ky_lo, ky_hi = kx.min(), kx.max(), ky.min(), ky.max()
    else:
        kx_lo = kx_hi = ky_lo = ky_hi = 0
    acc = np.zeros((h, n))
    idx = np.empty(n, dtype=np.int64)
    # point-major, positions innermost: consecutive look-ups walk the lattice, which is local
    # in the table (cache-friendly), where scan-point-major order jumps across the map
    for j in range(h):
        row = acc[j]
        for i in range(m):
            x0, y0 = qx[j, i], qy[j, i]
            if w > 0:
                bx, by = (px[0] + x0) * inv, (py[0] + y0) * inv
                fx, fy = math.floor(bx), math.floor(by)
                ix0, iy0 = np.int64(fx), np.int64(fy)
                if (bx - fx > _EDGE and fx + 1.0 - bx > _EDGE and by - fy > _EDGE
                        and fy + 1.0 - by > _EDGE and ix0 + w * kx_lo >= 0
                        and ix0 + w * kx_hi <= nx - 1 and iy0 + w * ky_lo >= 0
                        and iy0 + w * ky_hi <= ny - 1):
                    base = iy0 * nx + ix0
                    for p in range(n):
                        row[p] += flat[base + offset[p]]
                    continue
            for p in range(n):
                ix = min(max(np.int64(math.floor((px[p] + x0) * inv)), 0), nx - 1)
                iy = min(max(np.int64(math.floor((py[p] + y0) * inv)), 0), ny - 1)
                idx[p] = iy * nx + ix
            for p in range(n):
                row[p] += flat[idx[p]]
    out = np.empty((n, h))
    for p in range(n):
        for j in range(h):
            out[p, j] = acc[j, p] / m
    return out


@njit(cache=True, nogil=True)
def _before(v: float, f: int, w: float, g: int) -> bool:
    """Whether ``(v, f)`` comes before ``(w, g)``: lower score, ties by lower index."""
    return v < w or (v == w and f < g)


@njit(cache=True, nogil=True)
def smallest_kernel(scores: np.ndarray, count: int) -> np.ndarray:
    """Indices of the ``count`` lowest of ``scores`` ``(N,)``, ordered by score, ties by index (a
    max-heap of the best so far: one comparison for most entries)."""
    k = min(count, scores.shape[0])
    heap = np.empty(k, dtype=np.int64)          # heap[0]: the worst kept
    for f in range(k):                          # the first k, then sift each up
        heap[f] = f
        c = f
        while c > 0:
            parent = (c - 1) // 2
            if _before(scores[heap[parent]], heap[parent], scores[heap[c]], heap[c]):
                heap[parent], heap[c] = heap[c], heap[parent]
                c = parent
            else:
                break
    for f in range(k, scores.shape[0]):
        v = scores[f]
        if not _before(v, f, scores[heap[0]], heap[0]):
            continue
        heap[0] = f                              # replace the worst, sift it down
        c = 0
        while True:
            a, b = 2 * c + 1, 2 * c + 2
            big = c
            if a < k and _before(scores[heap[big]], heap[big], scores[heap[a]], heap[a]):
                big = a
            if b < k and _before(scores[heap[big]], heap[big], scores[heap[b]], heap[b]):
                big = b
            if big == c:
                break
            heap[c], heap[big] = heap[big], heap[c]
            c = big
    # sorted: by index first, then a stable sort by score
    kept = np.sort(heap)
    return kept[np.argsort(scores[kept], kind="mergesort")]


@njit(cache=True, nogil=True)
def pose_scores_kernel(table: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       points: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Mean distance-field value ``(K,)`` of ``points`` ``(M, 2)`` at each of ``(K, 3)`` poses."""
    ny, nx = table.shape
    out = np.zeros(poses.shape[0])
    inv = 1.0 / resolution
    for k in range(poses.shape[0]):
        c, s = math.cos(poses[k, 2]), math.sin(poses[k, 2])
        px, py = poses[k, 0] - origin_x, poses[k, 1] - origin_y
        acc = 0.0
        for i in range(points.shape[0]):
            ix = int(math.floor((px + c * points[i, 0] - s * points[i, 1]) * inv))
            iy = int(math.floor((py + s * points[i, 0] + c * points[i, 1]) * inv))
            acc += table[min(max(iy, 0), ny - 1), min(max(ix, 0), nx - 1)]
        out[k] = acc / points.shape[0]
    return out


@njit(cache=True, nogil=True)
def separated_kernel(poses: np.ndarray, count: int, separation: float) -> np.ndarray:
    """Indices of up to ``count`` of the ``(N, 3)`` poses (in the given order) whose positions are
    at least ``separation`` metres from every earlier kept one."""
    keep = np.empty(count, dtype=np.int64)
    n_kept = 0
    s2 = separation * separation
    for i in range(poses.shape[0]):
        ok = True
        for k in range(n_kept):
            dx = poses[i, 0] - poses[keep[k], 0]
            dy = poses[i, 1] - poses[keep[k], 1]
            if dx * dx + dy * dy < s2:
                ok = False
                break
        if ok:
            keep[n_kept] = i
            n_kept += 1
            if n_kept == count:
                break
    return keep[:n_kept]


@njit(cache=True, nogil=True)
def candidates_kernel(table: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                      points: np.ndarray, stride: int, positions: np.ndarray,
                      headings: np.ndarray, shortlist: int, count: int,
                      separation: float, step: float) -> tuple[np.ndarray, np.ndarray, int]:
    """The coarse search of :mod:`tfloc.tfplus.coarse` in one call: every position × heading
    scored on every ``stride``-th of ``points`` (:func:`grid_scores_kernel`; positions on a
    lattice of ``step`` metres, 0: none), the ``shortlist``
    lowest (:func:`smallest_kernel`: ties by index) rescored on all points
    (:func:`pose_scores_kernel`), ordered by that score (stable) and thinned to at most ``count``
    poses ``separation`` metres apart (:func:`separated_kernel`). Returns those candidates
    ``(C, 3)``, their scores ``(C,)`` and the size of the shortlist."""
    sub = np.ascontiguousarray(points[::stride])
    h = headings.shape[0]
    first = grid_scores_kernel(table, origin_x, origin_y, resolution, sub, positions,
                               headings, step).ravel()
    top = smallest_kernel(first, shortlist)
    poses = np.empty((top.shape[0], 3))
    for i in range(top.shape[0]):
        p, j = top[i] // h, top[i] % h
        poses[i, 0], poses[i, 1], poses[i, 2] = positions[p, 0], positions[p, 1], headings[j]
    scores = pose_scores_kernel(table, origin_x, origin_y, resolution, points, poses)
    order = np.argsort(scores, kind="mergesort")
    ordered = poses[order]
    keep = separated_kernel(ordered, count, separation)
    return ordered[keep], scores[order][keep], top.shape[0]




@njit(cache=True, nogil=True)
def coarse_kernel(points: np.ndarray, positions: np.ndarray, x: float, y: float, heads: np.ndarray,
                  coarse: tuple) -> tuple[np.ndarray, int]:
    """``tf-plus``'s coarse search from the lattice ``positions`` ``(N, 2)`` (the initial guess
    ``(x, y)`` alone if there are none) × ``heads``: :func:`candidates_kernel` on every
    ``stride``-th of ``points``, the stride giving about ``coarse_points`` of them (or
    ``scan_stride`` if that is 0). ``coarse`` is :func:`tfloc.tfplus.config.coarse_search`'s
    tuple. Returns the candidates and the evaluations counted (positions × headings + the
    shortlist)."""
    table, ox, oy, res, coarse_points, scan_stride, shortlist, count, separation, step = coarse
    if positions.shape[0] == 0:
        positions = np.empty((1, 2))
        positions[0, 0], positions[0, 1] = x, y
    stride = max(1, points.shape[0] // coarse_points) if coarse_points else scan_stride
    cands, _, rescored = candidates_kernel(table, ox, oy, res, points, stride, positions, heads,
                                           shortlist, count, separation, step)
    return cands, positions.shape[0] * heads.shape[0] + rescored
