"""Compiled kernels of the refinement against virtual scans (:func:`tfloc.tfplus.refine.refine`).

:func:`pairs_kernel` pairs scan points with a virtual scan's points and sums one Gauss–Newton
system (on any map); on a vector map :func:`refine_vector_kernel` runs the whole refinement, ray
casts and pruning included, in one call. From Python an iteration was some 20 numpy calls and
temporaries, more than its arithmetic. The same arithmetic in the same order (the ray cast is
:func:`tfloc.maps._raycast.raycast_segments` itself; the beams' cos/sin come from numpy, computed
once by the caller), so the poses are those of the step-by-step loop bit for bit
(``tests/tfplus/test_fused_equivalence.py``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tfloc.maps._raycast import _atan2, raycast_segments
from tfloc.paper.turning import _pairwise_sum

_SURE = 1e-12  # relative: squared lengths this far apart order their hypot()s the same way


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
def _sides(fx: float, fy: float, bx: float, by: float) -> int:
    """Which tangent :func:`tfloc.tfplus.refine._virtual_geometry` takes at a virtual point, with
    steps ``f`` to the next and ``b`` from the previous point (NaN: none): 0 the central
    difference (``lf < 3·lb`` and ``lb < 3·lf``), -1 the forward step (``lf ≤ lb``), 1 the
    backward one, for the lengths ``lf = hypot(f)``, ``lb = hypot(b)`` (NaN as +inf).

    Decided from the squared lengths where they are clearly apart (``hypot`` is within an ulp of
    the true length, so the comparisons agree) and from ``hypot`` itself where they are within
    ``_SURE``: the same decisions as with ``hypot`` alone, for a third of its calls."""
    sf, sb = fx * fx + fy * fy, bx * bx + by * by
    if not (math.isnan(sf) or math.isnan(sb) or math.isinf(sf) or math.isinf(sb)):
        lo, hi = 1.0 - _SURE, 1.0 + _SURE
        c1 = 1 if sf < 9.0 * sb * lo else (0 if sf > 9.0 * sb * hi else -1)   # lf < 3·lb?
        c2 = 1 if sb < 9.0 * sf * lo else (0 if sb > 9.0 * sf * hi else -1)   # lb < 3·lf?
        c3 = 1 if sf < sb * lo else (0 if sf > sb * hi else -1)               # lf ≤ lb?
        if c1 >= 0 and c2 >= 0 and (c1 == 1 and c2 == 1 or c3 >= 0):
            if c1 == 1 and c2 == 1:
                return 0
            return -1 if c3 == 1 else 1
    lf, lb = math.hypot(fx, fy), math.hypot(bx, by)
    if math.isnan(lf):
        lf = np.inf
    if math.isnan(lb):
        lb = np.inf
    if lf < 3 * lb and lb < 3 * lf:
        return 0
    return -1 if lf <= lb else 1


@njit(cache=True, nogil=True, error_model="numpy")
def virtual_geometry_kernel(ranges: np.ndarray, cos_a: np.ndarray, sin_a: np.ndarray,
                            max_range: float) -> tuple[np.ndarray, np.ndarray]:
    """Virtual points ``(K, n, 2)`` (NaN for no return) and unit line normals ``(K, n, 2)`` of
    the virtual scans ``ranges`` ``(K, n)`` (metres; beam directions ``cos_a``, ``sin_a``):
    :func:`tfloc.tfplus.refine._virtual_geometry`, element by element."""
    k_n, n = ranges.shape
    q = np.empty((k_n, n, 2))
    normal = np.empty((k_n, n, 2))
    nan = np.nan
    for k in range(k_n):
        for b in range(n):
            r = ranges[k, b]
            if not (np.isfinite(r) and r > 0.0 and r < max_range):
                r = nan
            q[k, b, 0] = cos_a[b] * r
            q[k, b, 1] = sin_a[b] * r
        for b in range(n):
            if b < n - 1:
                fx, fy = q[k, b + 1, 0] - q[k, b, 0], q[k, b + 1, 1] - q[k, b, 1]
            else:
                fx, fy = nan, nan
            if b > 0:
                bx, by = q[k, b, 0] - q[k, b - 1, 0], q[k, b, 1] - q[k, b - 1, 1]
            else:
                bx, by = nan, nan
            side = _sides(fx, fy, bx, by)
            if side == 0:                       # central difference on smooth stretches
                tx, ty = fx + bx, fy + by
            elif side < 0:                      # the shorter side across a jump or a corner
                tx, ty = fx, fy
            else:
                tx, ty = bx, by
            norm = math.hypot(tx, ty)
            normal[k, b, 0] = -ty / norm                # numpy's x / 0 (error_model)
            normal[k, b, 1] = tx / norm
    return q, normal


@njit(cache=True, nogil=True)
def refine_virtual_kernel(poses: np.ndarray, points: np.ndarray, rel_angles: np.ndarray,
                          cos_a: np.ndarray, sin_a: np.ndarray, angle_min: float,
                          resolution: float, segs: np.ndarray, index: tuple, max_range: float,
                          gates: np.ndarray, inner: int, window: int,
                          damping: float) -> tuple[np.ndarray, np.ndarray]:
    """Iterations of :func:`tfloc.tfplus.refine.refine` on a vector map (segments ``segs``, their
    buckets ``index``), one
    per gate of ``gates``: the refined poses ``(K, 3)`` and the signed residuals ``(K, M)`` of
    the last Gauss–Newton step of the last iteration (NaN: unpaired), which the pruning ranks
    by. ``rel_angles`` are the beam angles (radians, relative to the heading), ``cos_a``/
    ``sin_a`` their cos/sin as numpy computes them, ``angle_min``/``resolution`` the laser's
    (radians)."""
    poses = poses.copy()
    k_n, m = poses.shape[0], points.shape[0]
    r = np.full((k_n, m), np.nan)
    eye = np.eye(3)
    for it in range(gates.shape[0]):
        virtual = raycast_segments(poses, rel_angles, segs, max_range, index)
        q, normal = virtual_geometry_kernel(virtual, cos_a, sin_a, max_range)
        delta = np.zeros_like(poses)
        for _ in range(inner):
            h, g, r = pairs_kernel(points, delta, q, normal, angle_min, resolution, window,
                                   gates[it], cos_a, sin_a)
            for k in range(k_n):
                paired = 0
                for i in range(m):
                    if not math.isnan(r[k, i]):
                        paired += 1
                if paired >= 3:
                    step = np.linalg.solve(h[k] + damping * eye, g[k])
                    for a in range(3):
                        delta[k, a] -= step[a]
        for k in range(k_n):
            c, s = math.cos(poses[k, 2]), math.sin(poses[k, 2])
            x = poses[k, 0] + c * delta[k, 0] - s * delta[k, 1]
            y = poses[k, 1] + s * delta[k, 0] + c * delta[k, 1]
            poses[k, 0], poses[k, 1] = x, y
            poses[k, 2] = (poses[k, 2] + delta[k, 2] + np.pi) % (2.0 * np.pi) - np.pi
    return poses, r


@njit(cache=True, nogil=True)
def truncated_cost_kernel(residuals: np.ndarray, inlier_distance: float) -> np.ndarray:
    """:func:`tfloc.tfplus.refine.truncated_cost` of ``|residuals|`` ``(K, M)``, bit for bit."""
    k_n, m = residuals.shape
    out = np.empty(k_n)
    sq = np.empty(m)
    for k in range(k_n):
        for i in range(m):
            r = abs(residuals[k, i])
            r = inlier_distance if math.isnan(r) else min(r, inlier_distance)
            sq[i] = r * r
        out[k] = _pairwise_sum(sq) / m
    return out


@njit(cache=True, nogil=True)
def prune_index_kernel(poses: np.ndarray, cost: np.ndarray, keep: int, same: float) -> np.ndarray:
    """:func:`tfloc.tfplus.refine._prune_index`: ascending indices of the ``keep`` lowest-cost
    poses, a pose within ``same`` metres of a better kept one counted once."""
    kept = np.empty(keep, dtype=np.int64)
    n = 0
    for i in np.argsort(cost, kind="mergesort"):
        ok = True
        for t in range(n):
            j = kept[t]
            if not math.hypot(poses[i, 0] - poses[j, 0], poses[i, 1] - poses[j, 1]) >= same:
                ok = False
                break
        if ok:
            kept[n] = i
            n += 1
            if n == keep:
                break
    return np.sort(kept[:n])


@njit(cache=True, nogil=True)
def refine_vector_kernel(poses: np.ndarray, points: np.ndarray, rel_angles: np.ndarray,
                         cos_a: np.ndarray, sin_a: np.ndarray, angle_min: float,
                         resolution: float, segs: np.ndarray, index: tuple, max_range: float,
                         gates: np.ndarray, inner: int, window: int, damping: float,
                         prune_after: int, keep: int, inlier_distance: float) -> np.ndarray:
    """The whole of :func:`tfloc.tfplus.refine.refine` on a vector map in one call: the
    iterations up to ``prune_after`` (:func:`refine_virtual_kernel`), the pruning to the ``keep``
    best by truncated residual, the rest of the iterations."""
    n_it = gates.shape[0]
    prune_at = 0 < prune_after <= n_it
    cut = prune_after if prune_at else n_it
    if cut > 0:
        poses, r = refine_virtual_kernel(poses, points, rel_angles, cos_a, sin_a, angle_min,
                                         resolution, segs, index, max_range, gates[:cut], inner, window,
                                         damping)
        if prune_at and poses.shape[0] > keep:
            cost = truncated_cost_kernel(r, inlier_distance)
            poses = poses[prune_index_kernel(poses, cost, keep, 0.05)]
    if cut < n_it:
        poses, _ = refine_virtual_kernel(poses, points, rel_angles, cos_a, sin_a, angle_min,
                                         resolution, segs, index, max_range, gates[cut:], inner, window,
                                         damping)
    return poses
