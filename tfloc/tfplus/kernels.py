"""Compiled kernels behind ``tf-plus`` (numba, one core): grid scoring and point-to-line pairs.

Same arithmetic as a numpy version, without its (K, M, W, 2) temporaries, which dominated
the matcher's time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tfloc.maps._gridcast import _entry, _start, _step
from tfloc.maps._raycast import _atan2
from tfloc.maps.inside import raster_code

_EDGE = 1e-6  # cells: a lattice look-up this close to a cell edge is made the plain way


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
def _beam_of(x: float, y: float, v: float, angle_min: float, resolution: float) -> int:
    """``round((atan2(y, x) − angle_min) / resolution)``, the beam nearest the bearing of
    ``(x, y)``, given ``v``, that bearing in beams from the cheap
    :func:`~tfloc.maps._raycast._atan2` (error below 1e-5 rad): from ``v`` itself, and from
    ``math.atan2`` where the two could round differently (within 1e-4 rad of a half step)."""
    if abs(v - math.floor(v) - 0.5) > 1e-4 / resolution:
        return int(math.floor(v + 0.5))
    return int(round((math.atan2(y, x) - angle_min) / resolution))


_SHRINK = 1.0 - 1e-9  # a line's squared distance, less 1e-9 of it and 1e-18 m² for rounding, bounds a pair's


@njit(cache=True, nogil=True)
def pairs_kernel(points: np.ndarray, delta: np.ndarray, q: np.ndarray, normal: np.ndarray,
                 angle_min: float, resolution: float, window: int, gate: float,
                 cos_a: np.ndarray, sin_a: np.ndarray,
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Point-to-line pairs of each candidate and one Gauss–Newton system.

    ``points`` ``(M, 2)`` real points (sensor frame), ``delta`` ``(K, 3)`` current corrections
    ``(tx, ty, φ)``, ``q``/``normal`` ``(K, n, 2)`` virtual points/unit normals (NaN: none),
    ``cos_a``/``sin_a`` ``(n,)`` the beams' directions (the virtual points lie on them).
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
    vx = np.empty(n)          # a candidate's virtual points, +inf where there is none (never
    vy = np.empty(n)          # nearer than the gate: the same pairs as skipping them)
    stops = (window + 1.0) * resolution < 0.5 * math.pi - 0.01   # the lines' distances grow
    place = np.empty((m, 4))     # a point rotated (x, y), then moved (x, y)
    bearing = np.empty(m)        # its bearing in beams (cheap), and its beam
    beam = np.empty(m, dtype=np.int64)
    for k in range(k_n):
        for j in range(n):
            if math.isnan(q[k, j, 0]) or math.isnan(normal[k, j, 0]):
                vx[j], vy[j] = np.inf, 0.0
            else:
                vx[j], vy[j] = q[k, j, 0], q[k, j, 1]
        c, s = math.cos(delta[k, 2]), math.sin(delta[k, 2])
        # first every point's place and bearing (the cheap bearing, then its beam), so that the
        # search's branches below do not wait on a bearing's long chain of arithmetic
        for i in range(m):
            rx = c * points[i, 0] - s * points[i, 1]
            ry = s * points[i, 0] + c * points[i, 1]
            place[i, 0], place[i, 1] = rx, ry
            place[i, 2], place[i, 3] = rx + delta[k, 0], ry + delta[k, 1]
            bearing[i] = (_atan2(place[i, 3], place[i, 2]) - angle_min) / resolution
        for i in range(m):
            beam[i] = _beam_of(place[i, 2], place[i, 3], bearing[i], angle_min, resolution)
        # the sums in registers, each in point order as it was in hh/gg (H is symmetric exactly:
        # a·b and b·a are the same float)
        h00 = h01 = h02 = h11 = h12 = h22 = g0 = g1 = g2 = 0.0
        for i in range(m):
            rx, ry, x, y = place[i, 0], place[i, 1], place[i, 2], place[i, 3]
            j0, v = beam[i], bearing[i]
            lo, hi = max(j0 - window, 0), min(j0 + window, n - 1)
            if lo > hi:
                continue
            # the nearest virtual point within the window (the lowest beam among equals), searched
            # outwards from the bearing: each side stops at a beam whose line lies farther from
            # the point than the best so far (on that side, past the bearing and within 90° of
            # it, every later beam's line lies farther still)
            best, bj = gate * gate, -1
            left = min(max(j0, lo), hi)
            right = left + 1
            while left >= lo or right <= hi:
                if left >= lo:
                    off = cos_a[left] * y - sin_a[left] * x      # signed distance to the line
                    if stops and off * off * _SHRINK - 1e-18 > best and left < v - 0.01:
                        left = lo - 1
                    else:
                        dx, dy = x - vx[left], y - vy[left]
                        d2 = dx * dx + dy * dy
                        if d2 < best or (d2 == best and left < bj):
                            best, bj = d2, left
                        left -= 1
                if right <= hi:
                    off = cos_a[right] * y - sin_a[right] * x
                    if stops and off * off * _SHRINK - 1e-18 > best and right > v + 0.01:
                        right = hi + 1
                    else:
                        dx, dy = x - vx[right], y - vy[right]
                        d2 = dx * dx + dy * dy
                        if d2 < best:
                            best, bj = d2, right
                        right += 1
            if bj < 0:
                continue
            nx, ny = normal[k, bj, 0], normal[k, bj, 1]
            r = nx * (x - q[k, bj, 0]) + ny * (y - q[k, bj, 1])
            res[k, i] = r
            j0_, j1_, j2_ = nx, ny, -nx * ry + ny * rx
            g0 += j0_ * r
            g1 += j1_ * r
            g2 += j2_ * r
            h00 += j0_ * j0_
            h01 += j0_ * j1_
            h02 += j0_ * j2_
            h11 += j1_ * j1_
            h12 += j1_ * j2_
            h22 += j2_ * j2_
        gg[k, 0], gg[k, 1], gg[k, 2] = g0, g1, g2
        hh[k, 0, 0], hh[k, 0, 1], hh[k, 0, 2] = h00, h01, h02
        hh[k, 1, 0], hh[k, 1, 1], hh[k, 1, 2] = h01, h11, h12
        hh[k, 2, 0], hh[k, 2, 1], hh[k, 2, 2] = h02, h12, h22
    return hh, gg, res


@njit(cache=True, nogil=True)
def _to_nearest(field: tuple[np.ndarray, float, float, float, np.ndarray], px: float, py: float,
                c: float, s: float, x: float, y: float) -> tuple[float, float, int, float, float]:
    """The scan point ``(x, y)`` (sensor frame) at the pose ``(px, py)`` turned by ``(c, s)``,
    against ``field`` = (nearest, origin x, origin y, 1 / resolution, map points) (see
    :func:`field_pairs_kernel`): its offset from the sensor ``(ox, oy)`` (world axes), the index
    ``j`` of its cell's nearest map point (-1: none; cell indices clipped into the lattice) and its
    offset ``(dx, dy)`` from that point (NaN if none)."""
    nearest, origin_x, origin_y, inv, map_points = field
    ny, nx = nearest.shape
    ox = c * x - s * y
    oy = s * x + c * y
    wx, wy = px + ox, py + oy
    ix = min(max(int(math.floor((wx - origin_x) * inv)), 0), nx - 1)
    iy = min(max(int(math.floor((wy - origin_y) * inv)), 0), ny - 1)
    j = nearest[iy, ix]
    if j < 0:
        return ox, oy, j, np.nan, np.nan
    return ox, oy, j, wx - map_points[j, 0], wy - map_points[j, 1]


@njit(cache=True, nogil=True)
def field_pairs_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       map_points: np.ndarray, map_normals: np.ndarray, face_plus: np.ndarray,
                       face_minus: np.ndarray, points: np.ndarray, poses: np.ndarray,
                       offsets: np.ndarray, gate: float, slack: float, cell_weight: float,
                       face_weight: float,
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Point-to-line pairs of scan points with their nearest map points, and one Gauss–Newton system.

    ``nearest`` ``(ny, nx)``: index into the map points ``(N, 2)``, their unit normals ``(N, 2)``
    and the distances ``face_plus``/``face_minus`` ``(N,)`` from each point to its wall's surface
    along ``±normal`` of each cell's nearest map point (a
    :class:`~tfloc.tfplus.view.DistanceField`). ``points`` ``(M, 2)``: the scan (sensor frame);
    ``poses`` ``(K, 3)`` world poses, ``offsets`` ``(K,)`` how far (metres) the returns lie behind
    the walls' surfaces. Each world point ``w`` is paired with the map point ``q`` of its cell if
    ``|w − q| ≤ gate``. Its residual is ``n·(w − q)`` (metres), or with ``use_faces``, with ``n``
    turned to face the sensor, ``n·(w − q) − face + offset`` (``face`` the distance to the
    surface on the sensor's side).

    Returns, per pose, the normal equations ``H`` ``(K, 4, 4)`` and ``g`` ``(K, 4)`` in the
    additive parameters ``(x, y, θ, offset)`` (the offset's column is zero without faces), the
    residuals ``(K, M)`` (NaN: unpaired), and the ranking residual ``max(|n·(w − q)|, |w − q| −
    slack)`` ``(K, M)`` of every point, paired or not (the second term keeps a point beyond the
    end of a wall, on the wall's line, from counting as on it).
    """
    k_n, m = poses.shape[0], points.shape[0]
    hh = np.zeros((k_n, 4, 4))
    gg = np.zeros((k_n, 4))
    res = np.full((k_n, m), np.nan)
    rank = np.empty((k_n, m))
    field = (nearest, origin_x, origin_y, 1.0 / resolution, map_points)
    near = np.empty(m, dtype=np.int64)     # each point's nearest map point (-1: none) ...
    geo = np.empty((m, 4))                 # ... its offset from the sensor and from that point
    faces = face_weight > 0.0
    cw, fw = cell_weight, face_weight
    for k in range(k_n):
        px, py = poses[k, 0], poses[k, 1]
        c, s = math.cos(poses[k, 2]), math.sin(poses[k, 2])
        offset = offsets[k]
        # the sums in registers, each in point order (cell term, then face term) as it was in
        # hh/gg; a weighted product (w·a)·b is not (w·b)·a, so all 16 of H
        h00 = h01 = h02 = h03 = h10 = h11 = h12 = h13 = 0.0
        h20 = h21 = h22 = h23 = h30 = h31 = h32 = h33 = 0.0
        g0 = g1 = g2 = g3 = 0.0
        # first every point's nearest map point (independent look-ups the processor overlaps),
        # then the pairs, whose branches would otherwise wait on two dependent look-ups each
        for i in range(m):
            ox, oy, j, dx, dy = _to_nearest(field, px, py, c, s, points[i, 0], points[i, 1])
            near[i] = j
            geo[i, 0], geo[i, 1], geo[i, 2], geo[i, 3] = ox, oy, dx, dy
        for i in range(m):
            j = near[i]
            ox, oy, dx, dy = geo[i, 0], geo[i, 1], geo[i, 2], geo[i, 3]
            if j < 0:
                rank[k, i] = np.inf
                continue
            nxj, nyj = map_normals[j, 0], map_normals[j, 1]
            r = nxj * dx + nyj * dy
            dist = math.sqrt(dx * dx + dy * dy)
            rank[k, i] = max(abs(r), dist - slack)
            if dist > gate:
                continue
            res[k, i] = r
            a0, a1, a2 = nxj, nyj, -nxj * oy + nyj * ox          # the Jacobian (x, y, θ)
            w0, w1, w2 = cw * a0, cw * a1, cw * a2
            g0 += w0 * r
            g1 += w1 * r
            g2 += w2 * r
            h00 += w0 * a0
            h01 += w0 * a1
            h02 += w0 * a2
            h10 += w1 * a0
            h11 += w1 * a1
            h12 += w1 * a2
            h20 += w2 * a0
            h21 += w2 * a1
            h22 += w2 * a2
            if faces:
                if nxj * ox + nyj * oy > 0.0:          # the normal faces away from the sensor
                    nxj, nyj, rf = -nxj, -nyj, -r - face_minus[j]
                else:
                    rf = r - face_plus[j]
                rf += offset
                a0, a1, a2, a3 = nxj, nyj, -nxj * oy + nyj * ox, 1.0   # (x, y, θ, offset)
                w0, w1, w2, w3 = fw * a0, fw * a1, fw * a2, fw * a3
                g0 += w0 * rf
                g1 += w1 * rf
                g2 += w2 * rf
                g3 += w3 * rf
                h00 += w0 * a0
                h01 += w0 * a1
                h02 += w0 * a2
                h03 += w0 * a3
                h10 += w1 * a0
                h11 += w1 * a1
                h12 += w1 * a2
                h13 += w1 * a3
                h20 += w2 * a0
                h21 += w2 * a1
                h22 += w2 * a2
                h23 += w2 * a3
                h30 += w3 * a0
                h31 += w3 * a1
                h32 += w3 * a2
                h33 += w3 * a3
        hh[k, 0, 0], hh[k, 0, 1], hh[k, 0, 2], hh[k, 0, 3] = h00, h01, h02, h03
        hh[k, 1, 0], hh[k, 1, 1], hh[k, 1, 2], hh[k, 1, 3] = h10, h11, h12, h13
        hh[k, 2, 0], hh[k, 2, 1], hh[k, 2, 2], hh[k, 2, 3] = h20, h21, h22, h23
        hh[k, 3, 0], hh[k, 3, 1], hh[k, 3, 2], hh[k, 3, 3] = h30, h31, h32, h33
        gg[k, 0], gg[k, 1], gg[k, 2], gg[k, 3] = g0, g1, g2, g3
    return hh, gg, res, rank


@njit(cache=True, nogil=True)
def face_depths_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       map_points: np.ndarray, map_normals: np.ndarray, face_plus: np.ndarray,
                       face_minus: np.ndarray, points: np.ndarray, poses: np.ndarray,
                       gate: float) -> np.ndarray:
    """How deep (metres) each scan point lies behind its wall's surface on the sensor's side
    (``(K, M)``; NaN if its nearest map point is farther than ``gate``); see
    :func:`field_pairs_kernel` for the arguments."""
    k_n, m = poses.shape[0], points.shape[0]
    out = np.full((k_n, m), np.nan)
    field = (nearest, origin_x, origin_y, 1.0 / resolution, map_points)
    for k in range(k_n):
        px, py = poses[k, 0], poses[k, 1]
        c, s = math.cos(poses[k, 2]), math.sin(poses[k, 2])
        for i in range(m):
            ox, oy, j, dx, dy = _to_nearest(field, px, py, c, s, points[i, 0], points[i, 1])
            if j < 0 or dx * dx + dy * dy > gate * gate:
                continue
            r = map_normals[j, 0] * dx + map_normals[j, 1] * dy
            if map_normals[j, 0] * ox + map_normals[j, 1] * oy > 0.0:
                out[k, i] = r + face_minus[j]
            else:
                out[k, i] = face_plus[j] - r
    return out


@njit(cache=True, nogil=True)
def refine_field_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                        map_points: np.ndarray, map_normals: np.ndarray, face_plus: np.ndarray,
                        face_minus: np.ndarray, points: np.ndarray, poses: np.ndarray,
                        offsets: np.ndarray, gates: np.ndarray, inner: int, offset_gate: float,
                        faces: bool, face_weight: float, cell_weight: float, damping: float,
                        offset_weight: float, offset_prior: float, max_depth: float,
                        started: bool) -> bool:
    """Gauss–Newton iterations of :func:`tfloc.tfplus.refine.refine_to_field`, one per gate of ``gates``
    × ``inner``, on ``poses`` ``(K, 3)`` and ``offsets`` ``(K,)`` in place (see there and
    :func:`field_pairs_kernel`). Returns whether the depth offsets have been started."""
    k_n = poses.shape[0]
    eye = np.eye(4)
    for it in range(gates.shape[0]):
        gate = gates[it]
        late = faces and gate <= offset_gate
        if late and not started:
            started = True
            d = face_depths_kernel(nearest, origin_x, origin_y, resolution, map_points, map_normals,
                                   face_plus, face_minus, points, poses, gate)
            for k in range(k_n):
                v = d[k][~np.isnan(d[k])]
                offsets[k] = min(max(np.median(v), 0.0), max_depth) if v.size else offset_prior
        fw = face_weight if late else 0.0
        cw = cell_weight if late else 1.0
        for _ in range(inner):
            h, g, r, _ = field_pairs_kernel(nearest, origin_x, origin_y, resolution, map_points,
                                            map_normals, face_plus, face_minus, points, poses,
                                            offsets, gate, resolution, cw, fw)
            for k in range(k_n):
                paired = 0
                for i in range(r.shape[1]):
                    if not math.isnan(r[k, i]):
                        paired += 1
                if paired < 3:
                    continue
                hk = h[k] + damping * eye
                gk = g[k].copy()
                hk[3, 3] += offset_weight
                gk[3] += offset_weight * (offsets[k] - offset_prior)
                step = np.linalg.solve(hk, gk)
                poses[k, 0] -= step[0]
                poses[k, 1] -= step[1]
                poses[k, 2] = (poses[k, 2] - step[2] + np.pi) % (2 * np.pi) - np.pi
                offsets[k] -= step[3]
    return started


@njit(cache=True, nogil=True)
def see_through_kernel(occ: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       poses: np.ndarray, angles: np.ndarray, ranges: np.ndarray,
                       max_range: float, margin: float) -> np.ndarray:
    """Which beams ``(K, n)`` of the real scan ``ranges`` ``(n,)`` (metres, ``angles`` relative to
    the sensor) the occupied grid ``occ`` says cannot be, at each of ``(K, 3)`` poses: a return
    more than ``margin`` beyond the far side of the first wall the beam meets (where the first
    run of occupied cells ends: a wall drawn several cells thick holds returns anywhere inside it),
    or no return (NaN, inf, ≥ ``max_range``) where the beam meets a wall within ``max_range``.
    Each beam is followed only as far as it needs to be."""
    H, W = occ.shape
    k_n, n = poses.shape[0], angles.shape[0]
    out = np.zeros((k_n, n), dtype=np.bool_)
    for k in range(k_n):
        x0, y0 = (poses[k, 0] - origin_x) / resolution, (poses[k, 1] - origin_y) / resolution
        for b in range(n):
            r = ranges[b]
            ret = r > 0.0 and r < max_range            # False for NaN
            limit = (r - margin) / resolution if ret else max_range / resolution
            if limit <= 0.0:
                continue
            a = poses[k, 2] + angles[b]
            dx, dy = math.cos(a), math.sin(a)
            t0, t1 = _entry(x0, y0, dx, dy, W, H)
            if t0 > t1 or t0 > limit:
                continue
            t1 = min(t1, limit)
            i, j, sx, sy, tdx, tdy, tx, ty = _start(x0, y0, dx, dy, t0, W, H)
            t = t0
            inside = False
            while t <= t1:
                if occ[j, i]:
                    if not ret:
                        out[k, b] = True
                        break
                    inside = True
                elif inside:
                    out[k, b] = True                 # left the first wall before the return
                    break
                t = min(tx, ty)
                i, j, tx, ty, inside_grid = _step(i, j, sx, sy, tdx, tdy, tx, ty, W, H)
                if not inside_grid:
                    break
    return out


@njit(cache=True, nogil=True)
def lattice_kernel(centre_x: float, centre_y: float, offsets: np.ndarray, table: np.ndarray,
                   corner_x: float, corner_y: float, resolution: float, clearance: float,
                   area: tuple, free: tuple, sure: float) -> tuple[np.ndarray, bool]:
    """:func:`tfloc.tfplus.coarse.lattice`'s positions on a vector map, in one call: of the
    points ``centre + offsets`` ``(N, 2)``, those where the distance field (``table``, cells of
    ``resolution`` from the corner) is at least ``clearance`` (of the table's dtype), in the
    mapped area and in free space (:func:`tfloc.maps.inside.raster_code` on the area's and the
    free space's rings, ``Rings.kernel``), in order. Returns them ``(K, 2)`` and whether every point was decided
    (False: one lay too near a boundary for the compiled test; ask the map)."""
    h, w = table.shape
    flat = table.ravel()
    out = np.empty((offsets.shape[0], 2))
    k = 0
    for i in range(offsets.shape[0]):
        x, y = centre_x + offsets[i, 0], centre_y + offsets[i, 1]
        ix = min(max(np.int64(math.floor((x - corner_x) / resolution)), 0), w - 1)
        iy = min(max(np.int64(math.floor((y - corner_y) / resolution)), 0), h - 1)
        if not flat[iy * w + ix] >= clearance:
            continue
        code = raster_code(x, y, area, sure)
        if code < 0:
            return out[:0], False
        if code == 0:
            continue
        code = raster_code(x, y, free, sure)
        if code < 0:
            return out[:0], False
        if code == 1:
            out[k, 0], out[k, 1] = x, y
            k += 1
    return out[:k].copy(), True


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
def grid_lattice_kernel(centre_x: float, centre_y: float, offsets: np.ndarray, table: np.ndarray,
                        corner_x: float, corner_y: float, resolution: float, clearance: float,
                        origin_x: float, origin_y: float, cell: float, free: np.ndarray,
                        distance: np.ndarray, min_distance: float) -> np.ndarray:
    """:func:`tfloc.tfplus.coarse.lattice`'s positions on a grid map, in one call: of the points
    ``centre + offsets`` ``(N, 2)``, in order, those where the distance field (``table``, cells of
    ``resolution`` from its corner) is at least ``clearance`` (of the table's dtype) and that lie
    in a known free cell of the grid (cells of ``cell`` metres from ``origin``; ``free`` ``(H, W)``)
    whose centre is at least ``min_distance`` from every occupied cell's (``distance``): the
    tests of :meth:`tfloc.maps.grid.GridMap.in_bounds` and ``is_free``, element by element."""
    h, w = table.shape
    gh, gw = free.shape
    flat = table.ravel()
    out = np.empty((offsets.shape[0], 2))
    k = 0
    for n in range(offsets.shape[0]):
        x, y = centre_x + offsets[n, 0], centre_y + offsets[n, 1]
        ix = min(max(np.int64(math.floor((x - corner_x) / resolution)), 0), w - 1)
        iy = min(max(np.int64(math.floor((y - corner_y) / resolution)), 0), h - 1)
        if not flat[iy * w + ix] >= clearance:
            continue
        i = np.int64(math.floor((x - origin_x) / cell))
        j = np.int64(math.floor((y - origin_y) / cell))
        if i < 0 or i >= gw or j < 0 or j >= gh:
            continue
        if free[j, i] and distance[j, i] >= min_distance:
            out[k, 0], out[k, 1] = x, y
            k += 1
    return out[:k].copy()


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
