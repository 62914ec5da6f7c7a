"""``tf``'s whole search (Alg. 5's simplex and the outer iterations) in one compiled call, on a
vector map.

:meth:`tfloc.paper.matcher.TurningFunctionMatcher.localize` drives the simplex from Python: per
scan some 2 000 Function1 look-ups, each a dictionary hit or a compiled evaluation, with list
sorts and small numpy arrays between them. :func:`search_kernel` runs the same steps with the
same arithmetic in the same order (the stable sort of three vertices, the first minimum, Python's
float ``%``, ``hypot``), caching Function1 by position exactly as the Python ``dict`` does (keys
are the positions' exact values; the cache is cleared after every outer iteration), and draws
nothing: the initial simplices' random directions come from the caller's generator, one per
outer iteration in order. It gives up (status -1) where it could not follow Python exactly — a
position too near the free space's boundary for the compiled free test, or a NaN Err, whose
comparisons Python's sort would order its own way — and the caller then runs the Python search
from the start. ``tests/tfplus/test_fused_equivalence.py`` compares both on scans of the office maps.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.typed import Dict

from .kernels import function1_kernel

_KEY = types.UniTuple(types.float64, 2)
_VALUE = types.UniTuple(types.float64, 3)


@njit(cache=True, nogil=True)
def _wrap(a: float) -> float:
    """:func:`tfloc.core.pose.wrap_angle` (numba's float ``%`` is Python's)."""
    return (a + np.pi) % (2.0 * np.pi) - np.pi


@njit(cache=True, nogil=True)
def _stable_order3(keys: np.ndarray) -> tuple[int, int, int]:
    """The order of three (non-NaN) keys, lowest first, equal keys in their given order: what
    Python's stable ``list.sort`` gives."""
    a, b, c = 0, 1, 2
    if keys[b] < keys[a]:
        a, b = b, a
    if keys[c] < keys[b]:
        b, c = c, b
        if keys[b] < keys[a]:
            a, b = b, a
    return a, b, c


@njit(cache=True, nogil=True)
def _f(cache, x: float, y: float, theta_v: float, args, misses: np.ndarray) -> float:
    """Function1's Err at ``(x, y)`` through the cache, a new evaluation counted in
    ``misses[0]``; NaN where it gave up (see the module notes)."""
    key = (x, y)
    if key in cache:
        return cache[key][0]
    (offsets, rings, sure, rel_angles, segs, index, directions, max_range, spacing, window, t,
     line_threshold, close_through_origin, along_path, l1, real_breaks, real_angles,
     penalty) = args
    code, e, h, r = function1_kernel(x, y, theta_v, offsets, rings, sure, rel_angles, segs, index,
                                     directions, max_range, spacing, window, t, line_threshold,
                                     close_through_origin, along_path, l1, real_breaks,
                                     real_angles, penalty)
    if code < 0 or np.isnan(e):
        return np.nan
    cache[key] = (e, h, r)
    misses[0] += 1
    return e


@njit(cache=True, nogil=True)
def _simplex(cache, x: float, y: float, th: float, size: float, phi: float, xy_tol: float,
             err_threshold: float, max_iterations: int, args,
             misses: np.ndarray) -> tuple[bool, float, float, int]:
    """:func:`tfloc.paper.matcher.simplex` from ``(x, y)`` at heading ``th``: ``(answered, best
    x, best y, iterations)``, new evaluations counted in ``misses[0]``; not answered: gave up."""
    px = np.array([x, x + size * math.cos(phi), x + size * math.cos(phi + np.pi / 3)])
    py = np.array([y, y + size * math.sin(phi), y + size * math.sin(phi + np.pi / 3)])
    keys = np.empty(3)
    it = 0
    while True:
        for v in range(3):                      # f of each vertex, in list order
            keys[v] = _f(cache, px[v], py[v], th, args, misses)
            if np.isnan(keys[v]):
                return False, 0.0, 0.0, 0
        if it >= max_iterations:                # min(pts, key=f): the first lowest
            b = 0
            for v in range(1, 3):
                if keys[v] < keys[b]:
                    b = v
            return True, px[b], py[b], it
        i, j, k = _stable_order3(keys)
        bx, by, nbx, nby, wx, wy = px[i], py[i], px[j], py[j], px[k], py[k]
        fb, fnb, fw = keys[i], keys[j], keys[k]
        if fb <= err_threshold or max(math.hypot(bx - nbx, by - nby),
                                      math.hypot(bx - wx, by - wy)) < xy_tol:
            return True, bx, by, it             # sorted: b is the first lowest
        it += 1
        cx, cy = 0.5 * (bx + nbx), 0.5 * (by + nby)
        rx, ry = cx + (cx - wx), cy + (cy - wy)
        fr = _f(cache, rx, ry, th, args, misses)
        if np.isnan(fr):
            return False, 0.0, 0.0, 0
        if fr < fb:
            ex, ey = rx + (rx - cx), ry + (ry - cy)
            fe = _f(cache, ex, ey, th, args, misses)
            if np.isnan(fe):
                return False, 0.0, 0.0, 0
            if fr < fe:
                wx, wy = rx, ry
            else:
                wx, wy = ex, ey
        elif fr < fnb:
            wx, wy = rx, ry
        else:
            if fr < fw:
                ccx, ccy = 0.5 * (cx + rx), 0.5 * (cy + ry)
            else:
                ccx, ccy = 0.5 * (cx + wx), 0.5 * (cy + wy)
            fc = _f(cache, ccx, ccy, th, args, misses)
            if np.isnan(fc):
                return False, 0.0, 0.0, 0
            if fc < fw:
                wx, wy = ccx, ccy
            else:                               # shrink towards B
                nbx, nby = 0.5 * (bx + nbx), 0.5 * (by + nby)
                wx, wy = 0.5 * (bx + wx), 0.5 * (by + wy)
        px[0], py[0], px[1], py[1], px[2], py[2] = bx, by, nbx, nby, wx, wy


@njit(cache=True, nogil=True)
def search_kernel(x0: float, y0: float, theta0: float, phis: np.ndarray, simplex_size: float,
                  xy_tol: float, theta_tol: float, err_threshold: float, max_iterations: int,
                  max_outer: int, rotation_correction: bool, heading_clamp: float,
                  keep_best: bool, args) -> tuple[int, float, float, float, bool, int, int,
                                                   float, int]:
    """The search of ``tf`` from the initial pose ``(x0, y0, theta0)``: :meth:`~tfloc.paper.
    matcher.TurningFunctionMatcher.localize`'s loop (the other arguments are :class:`~tfloc.
    paper.matcher.TfConfig`'s; ``phis`` the initial simplices' directions, one per outer
    iteration; ``args`` :func:`~tfloc.paper.kernels.function1_kernel`'s after the heading).

    Returns ``(status, x, y, theta, converged, iterations, new evaluations, err, outer)``; status
    1 answered, 0 gave up (the caller runs the Python search)."""
    cache = Dict.empty(key_type=_KEY, value_type=_VALUE)
    misses = np.zeros(1, dtype=np.int64)
    x, y, th = x0, y0, theta0
    err = _f(cache, x, y, th, args, misses)     # Function1 at the VP
    if np.isnan(err):
        return 0, x, y, th, False, 0, 0, 0.0, 0
    size = simplex_size
    iters, outer, converged = 0, 0, False
    have_best, best_err, best_x, best_y, best_th = False, 0.0, x, y, th
    while outer < max_outer:
        outer += 1
        ok, sx, sy, n_it = _simplex(cache, x, y, th, size, phis[outer - 1], xy_tol,
                                    err_threshold, max_iterations, args, misses)
        if not ok:
            return 0, x, y, th, False, 0, 0, 0.0, 0
        iters += n_it
        err, h, r = cache[(sx, sy)]             # evaluated by the simplex at this heading
        theta = _wrap(h - r) if rotation_correction else h
        if math.isfinite(heading_clamp):
            change = min(max(_wrap(theta - theta0), -heading_clamp), heading_clamp)
            theta = _wrap(theta0 + change)
        if not have_best or err < best_err:
            have_best, best_err, best_x, best_y, best_th = True, err, sx, sy, theta
        moved = math.hypot(sx - x, sy - y)
        turned = abs(_wrap(theta - th))
        x, y, th = sx, sy, theta
        size = max(size / 2.0, 10 * xy_tol)
        cache.clear()
        if err <= err_threshold or (moved < xy_tol and turned < theta_tol):
            converged = True
            break
    if keep_best and have_best:
        err, x, y, th = best_err, best_x, best_y, best_th
    return 1, x, y, th, converged, iters, misses[0], err, outer
