"""Turning functions (Algorithm 4) and their matching (Sec. 4.3, Eq. 13).

A turning function Θ(s) gives, at arc length s ∈ [0, 1) of a polygon scaled to unit perimeter,
the direction of the edge there: the first edge's angle to the x axis, then plus each signed
turning angle (counter-clockwise positive). It is a step function; a convex counter-clockwise
polygon climbs by 2π over [0, 1).

Readings of Alg. 4: its per-vertex angle ``Vector(i)·Vector(i+1)`` is read as the turn from edge
i−1 to edge i (the literal indices skip the turn after the first edge and run past the last);
the angle of the scaled vectors is taken with ``atan2(cross, dot)``, which equals Eq. 11's
``arccos`` of unit vectors with Eq. 12's sign, and stays exact near 0 and π. The first edge's
cross product is read as ``V × Vector(1)`` so that its angle is counter-clockwise from x, as
the text says.

Matching (Sec. 4.3): the distance is Eq. 13's L2 norm ``(∫₀¹ |Θ_R − Θ_V − θ|² ds)^½`` (the "area
between the two graphs", with squared heights), minimised over the starting vertex of the
virtual polygon (a cyclic shift) and over a rotation offset θ. For a fixed shift the best θ is
the mean of ``Θ_R − Θ_V`` (Arkin et al. 1991), so the search over θ is exact and closed-form.

Sec. 4.3's own words describe the area itself: "Rectangles are created between two graphs because
they are in the form of histograms. Each rectangle's area is determined, and the area between the
two graphs is calculated by adding the total areas together." That is the L1 distance
``∫₀¹ |Θ_R − Θ_V − θ| ds`` (``err_norm="l1"``; :func:`_best_shift` with ``l1``); its best θ for
a fixed shift is the weighted median of ``Θ_R − Θ_V`` (weights = piece widths). ``tf`` uses
Eq. 13 (L2) by default.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from tfloc.core.pose import wrap_angle

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class TurningFunction:
    """A turning function: ``breaks`` (n+1,) from 0 to 1 and ``angles`` (n,) in radians,
    ``angles[i]`` holding on ``[breaks[i], breaks[i+1])``."""

    breaks: np.ndarray
    angles: np.ndarray

    @property
    def n_edges(self) -> int:
        return len(self.angles)

    def __call__(self, s: np.ndarray) -> np.ndarray:
        """Θ(s) for arc lengths ``s`` in [0, 1)."""
        idx = np.clip(np.searchsorted(self.breaks, s, side="right") - 1, 0, self.n_edges - 1)
        return self.angles[idx]


@njit(cache=True, nogil=True)
def _block_sum(a: np.ndarray, lo: int, n: int) -> float:
    """A leaf (n ≤ 128) of numpy's pairwise summation: eight accumulators, then the rest."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]     # the eight accumulators
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - (n % 8):
        q = lo + i
        r0 += a[q]
        r1 += a[q + 1]
        r2 += a[q + 2]
        r3 += a[q + 3]
        r4 += a[q + 4]
        r5 += a[q + 5]
        r6 += a[q + 6]
        r7 += a[q + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True, nogil=True)
def _pairwise_sum(a: np.ndarray) -> float:
    """``a.sum()`` in numpy's order (pairwise halves of ≤ 128-element blocks), so the kernels
    reproduce the numpy formulas bit for bit. Iterative (cached recursive numba functions are
    unreliable); an array of at most 128 is one leaf."""
    if a.shape[0] <= 128:
        return _block_sum(a, 0, a.shape[0])
    f_lo = np.empty(64, dtype=np.int64)
    f_n = np.empty(64, dtype=np.int64)
    f_stage = np.empty(64, dtype=np.int64)
    vals = np.empty(64)
    f_lo[0], f_n[0], f_stage[0] = 0, a.shape[0], 0
    sp, vp = 1, 0
    while sp > 0:
        top = sp - 1
        lo, n = f_lo[top], f_n[top]
        if n <= 128:
            vals[vp] = _block_sum(a, lo, n)
            vp += 1
            sp -= 1
            continue
        n2 = n // 2
        n2 -= n2 % 8
        if f_stage[top] == 0:          # left half next
            f_stage[top] = 1
            f_lo[sp], f_n[sp], f_stage[sp] = lo, n2, 0
            sp += 1
        elif f_stage[top] == 1:        # then the right half
            f_stage[top] = 2
            f_lo[sp], f_n[sp], f_stage[sp] = lo + n2, n - n2, 0
            sp += 1
        else:                          # both done: left + right
            vals[vp - 2] = vals[vp - 2] + vals[vp - 1]
            vp -= 1
            sp -= 1
    return vals[0]


@njit(cache=True, nogil=True)
def _turning(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Breaks and angles of :func:`turning_function` (empty when fewer than 3 edges remain)."""
    n = v.shape[0]
    angles, breaks = np.empty(n), np.empty(n + 1)
    k = _turning_into(v, np.empty(n), np.empty(n), np.empty(n), angles, breaks)
    if k < 3:
        return np.empty(0), np.empty(0)
    return breaks[:k + 1], angles[:k]


@njit(cache=True, nogil=True)
def _turning_into(v: np.ndarray, ex: np.ndarray, ey: np.ndarray, length: np.ndarray,
                  angles: np.ndarray, breaks: np.ndarray) -> int:
    """:func:`_turning` into ``angles[:k]`` and ``breaks[:k + 1]`` (the edges' vectors and
    lengths in ``ex``, ``ey``, ``length``; each ``len(v)`` long or more, ``breaks`` one more);
    returns the number of edges ``k`` (nothing written after the edges when ``k`` < 3)."""
    n = v.shape[0]
    k = 0
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        x, y = v[j, 0] - v[i, 0], v[j, 1] - v[i, 1]
        h = np.hypot(x, y)
        if h > 1e-12:
            ex[k], ey[k], length[k] = x, y, h
            k += 1
    if k < 3:
        return k
    acc = np.arctan2(ey[0], ex[0])
    angles[0] = acc
    for i in range(1, k):
        px, py = ex[i - 1], ey[i - 1]
        acc += np.arctan2(px * ey[i] - py * ex[i], px * ex[i] + py * ey[i])
        angles[i] = acc
    total = _pairwise_sum(length[:k])
    breaks[0] = 0.0
    c = 0.0
    for i in range(k):
        c += length[i]
        breaks[i + 1] = c / total
    breaks[k] = 1.0
    return k


def turning_function(vertices: np.ndarray) -> TurningFunction:
    """Algorithm 4: the turning function of the closed polygon ``vertices`` ``(n, 2)`` (metres).

    Edges run ``v_i → v_{i+1}`` and ``v_n → v_1``; zero-length edges are dropped. Needs at least
    3 distinct vertices.
    """
    v = np.asarray(vertices, dtype=float)
    if v.ndim != 2 or v.shape[1] != 2:
        v = v.reshape(-1, 2)
    breaks, angles = _turning(v)
    if len(angles) < 3:
        raise ValueError("a turning function needs a polygon with at least 3 edges")
    return TurningFunction(breaks, angles)


@dataclass(frozen=True)
class Match:
    """The best alignment of two turning functions.

    Attributes:
        distance: Eq. 13's Err (radians), ≥ 0.
        rotation: θ minimising it, in [-π, π): the real polygon is the virtual one rotated by
            this (radians).
        shift: the starting vertex of the virtual polygon that minimises it.
    """

    distance: float
    rotation: float
    shift: int


@njit(cache=True, nogil=True)
def _dot(a: np.ndarray, b: np.ndarray, n: int) -> float:
    """``a[:n]·b[:n]`` summed in the order of numpy's einsum on x86-64 (two interleaved
    accumulators, unrolled by four), so :func:`match` equals its numpy formulation bit for bit."""
    acc0, acc1 = 0.0, 0.0
    i = 0
    while n - i >= 8:
        t0, t1 = acc0, acc1
        for q in range(3, -1, -1):
            t0 = a[i + 2 * q] * b[i + 2 * q] + t0
            t1 = a[i + 2 * q + 1] * b[i + 2 * q + 1] + t1
        acc0, acc1 = t0, t1
        i += 8
    while i < n:
        acc0 = a[i] * b[i] + acc0
        if i + 1 < n:
            acc1 = a[i + 1] * b[i + 1] + acc1
        i += 2
    return acc0 + acc1


@njit(cache=True, nogil=True)
def _dot_squares(a: np.ndarray, b: np.ndarray, n: int) -> float:
    """``a[:n]·(b[:n]·b[:n])`` as :func:`_dot` of ``a`` and the rounded squares ``b * b`` (numpy's
    ``d2``), without the array of squares."""
    acc0, acc1 = 0.0, 0.0
    i = 0
    while n - i >= 8:
        t0, t1 = acc0, acc1
        for q in range(3, -1, -1):
            b0, b1 = b[i + 2 * q], b[i + 2 * q + 1]
            t0 = a[i + 2 * q] * (b0 * b0) + t0
            t1 = a[i + 2 * q + 1] * (b1 * b1) + t1
        acc0, acc1 = t0, t1
        i += 8
    while i < n:
        acc0 = a[i] * (b[i] * b[i]) + acc0
        if i + 1 < n:
            acc1 = a[i + 1] * (b[i + 1] * b[i + 1]) + acc1
        i += 2
    return acc0 + acc1


@njit(cache=True, nogil=True)
def _mod1(x: float) -> float:
    """``x % 1.0`` (Python's float modulo), without the library call for ``-1 < x < 1``."""
    if 0.0 < x < 1.0:
        return x
    if x == 0.0:
        return 0.0
    if -1.0 < x < 0.0:
        return x + 1.0
    return x % 1.0


@njit(cache=True, nogil=True)
def _pieces(rb: np.ndarray, ra: np.ndarray, vb: np.ndarray, va: np.ndarray, k: int,
            moved: np.ndarray, grid: np.ndarray, width: np.ndarray, d: np.ndarray) -> None:
    """The pieces of Θ_R − Θ_V with the virtual function started at its vertex ``k``: their
    widths into ``width`` and the (constant) differences into ``d`` (``n_r + n_v`` each)."""
    n_r, n_v = ra.shape[0], va.shape[0]
    g_n = n_r + 1 + n_v
    start = vb[k]
    for j in range(n_v):                   # virtual breaks re-started at vertex k, sorted
        moved[j] = _mod1(vb[k + j - n_v if k + j >= n_v else k + j] - start)
    for j in range(1, n_v):                # already sorted but for rounding ties
        x = moved[j]
        i = j - 1
        while i >= 0 and moved[i] > x:
            moved[i + 1] = moved[i]
            i -= 1
        moved[i + 1] = x
    i_r, i_v = 0, 0                        # merge with the real breaks
    for g in range(g_n):
        if i_v >= n_v or (i_r <= n_r and rb[i_r] <= moved[i_v]):
            grid[g] = rb[i_r]
            i_r += 1
        else:
            grid[g] = moved[i_v]
            i_v += 1
    p_r, p_v, was_wrapped = 0, 0, False    # searchsorted(..., "right") - 1 by pointers
    for g in range(g_n - 1):
        mid = 0.5 * (grid[g + 1] + grid[g])
        u = mid + start
        wrapped = u >= 1.0
        if wrapped:
            u = u - 1.0
            if not was_wrapped:
                p_v, was_wrapped = 0, True
        while p_r + 1 <= n_r and rb[p_r + 1] <= mid:
            p_r += 1
        while p_v + 1 <= n_v and vb[p_v + 1] <= u:
            p_v += 1
        theta_v = va[min(p_v, n_v - 1)] + (TWO_PI if wrapped else 0.0)
        width[g] = grid[g + 1] - grid[g]
        d[g] = ra[min(p_r, n_r - 1)] - theta_v


@njit(cache=True, nogil=True)
def _weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    """A minimiser θ of ``Σ weights·|values − θ|`` (weights ≥ 0, not all 0): the first value at
    which the cumulative weight (in value order) reaches half the total; where it reaches
    exactly half, the midpoint of that value and the next (every θ between them is a minimiser)."""
    n = values.shape[0]
    order = np.argsort(values, kind="mergesort")
    half = 0.5 * np.sum(weights)
    c = 0.0
    for i in range(n):
        c += weights[order[i]]
        if c >= half:
            v = values[order[i]]
            if c == half and i + 1 < n:
                return 0.5 * (v + values[order[i + 1]])
            return v
    return values[order[n - 1]]


@njit(cache=True, nogil=True)
def _best_shift(rb: np.ndarray, ra: np.ndarray, vb: np.ndarray, va: np.ndarray,
                l1: bool) -> tuple[float, float, int]:
    """The best cyclic shift of the virtual function and its rotation: (err², rot, shift) of
    :func:`match` (the rotation is the mean difference), or with ``l1`` (area, rot, shift) for
    Sec. 4.3's area between the graphs (radians × unit arc length): for a fixed shift the area
    is a convex, piecewise linear function of θ whose minimum lies at the weighted median of
    ``Θ_R − Θ_V`` over the pieces (weights = piece widths), not at the mean, so the search over
    θ is exact. One merge sweep per shift."""
    n_r, n_v = ra.shape[0], va.shape[0]
    g_n = n_r + 1 + n_v
    return _best_shift_into(rb, ra, vb, va, l1, np.empty(n_v), np.empty(g_n), np.empty(g_n - 1),
                            np.empty(g_n - 1))


@njit(cache=True, nogil=True)
def _best_shift_into(rb: np.ndarray, ra: np.ndarray, vb: np.ndarray, va: np.ndarray, l1: bool,
                     moved: np.ndarray, grid: np.ndarray, width: np.ndarray,
                     d: np.ndarray) -> tuple[float, float, int]:
    """:func:`_best_shift` with its work in ``moved`` (``n_v`` or more), ``grid``
    (``n_r + 1 + n_v`` or more), ``width`` and ``d`` (``n_r + n_v`` or more)."""
    n_r, n_v = ra.shape[0], va.shape[0]
    g_n = n_r + 1 + n_v
    best_err, best_rot, best_k = np.inf, 0.0, 0
    for k in range(n_v):
        _pieces(rb, ra, vb, va, k, moved, grid, width, d)
        if l1:
            rot = _weighted_median(d[:g_n - 1], width[:g_n - 1])
            err = 0.0
            for g in range(g_n - 1):
                err += width[g] * abs(d[g] - rot)
        else:
            rot = _dot(width, d, g_n - 1)
            err = _dot_squares(width, d, g_n - 1) - rot * rot
        if err < best_err:
            best_err, best_rot, best_k = err, rot, k
    return best_err, best_rot, best_k


@njit(cache=True, nogil=True)
def _match(rb: np.ndarray, ra: np.ndarray, vb: np.ndarray, va: np.ndarray) -> tuple[float, float, int]:
    """(err², rot, shift) of :func:`match`: one merge sweep per cyclic shift, O(n_v·(n_r + n_v))."""
    return _best_shift(rb, ra, vb, va, False)


def match(real: TurningFunction, virtual: TurningFunction) -> Match:
    """Sec. 4.3: min over starting vertex (of ``virtual``) and rotation of the L2 distance.

    For each starting vertex k, the two step functions are compared on the union of their
    breaks (the virtual breaks shifted by ``-breaks[k]`` modulo 1, its angles raised by 2π after
    the wrap); on each piece the difference is constant, so the integrals are exact sums.
    """
    err2, rot, k = _match(real.breaks, real.angles, virtual.breaks, virtual.angles)
    rotation = wrap_angle(float(rot))
    return Match(math.sqrt(max(err2, 0.0)), rotation, int(k))
