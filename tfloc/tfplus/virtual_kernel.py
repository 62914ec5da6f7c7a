"""The refinement against virtual scans on a vector map (:func:`tfloc.tfplus.refine.refine`),
fused into one compiled call per run of iterations.

Each iteration of :func:`~tfloc.tfplus.refine.refine` ray-casts the candidates' virtual scans,
derives their points and line normals, and makes ``inner`` Gauss–Newton steps; from Python that
is some 20 numpy calls and temporaries per iteration, more than the arithmetic itself. Here the
same steps run in one numba call, with the same arithmetic in the same order (the ray cast is
:func:`tfloc.maps._raycast.raycast_segments` itself; the beam directions' cos/sin come from
numpy, computed once by the caller), so the refined poses are identical
(``tests/test_fused_equivalence.py`` compares them with the step-by-step path bit for bit).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tfloc.maps._raycast import raycast_segments
from tfloc.paper.turning import _pairwise_sum

from .kernels import pairs_kernel

_SURE = 1e-12  # relative: squared lengths this far apart order their hypot()s the same way


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
