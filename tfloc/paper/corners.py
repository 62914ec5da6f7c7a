"""ShortStraw corner finding (Wolin et al. 2008) as the paper gives it: Algorithms 1–3.

Readings of the paper's text, each chosen because the literal text does not work:

* **Alg. 1 divides by a squared distance.** Its ``D ← ‖P1 − P2‖²`` followed by
  ``P3 = P1 + (P2 − P1)/D·S`` would put P3 at ``S/‖P1P2‖`` from P1, while the text says P3
  lies "exactly S Euclidean distance away from P1". We use the Euclidean distance ``D``.
  With the paper's S = 1 the test ``D > S`` is the same either way.
* **Alg. 1 starts with** ``P1 ← points_i`` (i = 2); we start at the first point and keep it
  (ShortStraw keeps it; without it the first corner would be lost).
* **Alg. 2 squares the straws** (``‖p(i−w) − p(i+w)‖²``) and thresholds them at
  ``median × t``. That is well defined, so we keep it: it equals an unsquared threshold of
  ``√t·median`` (t = 0.99 → 0.995). Every index below the threshold is a candidate (no
  local-minimum selection, as written); Alg. 3 then thins them.
* **Alg. 2 uses w = 1** where Wolin et al. use w = 3: the default follows the paper; the
  window is a parameter.
* **Alg. 1 walks chords, not the path.** Its formula steps from the last emitted point P1
  towards the next input point (a chord); its sentence says P3 lies "exactly S Euclidian distance
  away from the P1 in the slop direction of the straight line from P(i−1) to P(i)", and Wolin et
  al.'s RESAMPLE-POINTS walks the *path* through P(i−1), P(i), emitting a point every S of path
  length. :func:`resample` is the chord walk (the default), :func:`_resample_path_into` the path
  walk (``shortstraw(..., along_path=True)``). They differ only where the path turns within S.
* **Alg. 3 sums squared steps** (``PathD ← PathD + ‖p_i − p_{i+1}‖²``). For points resampled at
  spacing S that makes ``D/PathD`` scale as 1/S, so the test only means "straight" when S = 1.
  We sum the plain step lengths (ShortStraw's IS-LINE), which is identical at S = 1.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _emit(out: np.ndarray, m: int, x: float, y: float) -> int:
    """Write point ``m`` into ``out`` (unless ``out`` only counts, shape ``(0, 2)``); the new
    count, or -1 if ``out`` is full."""
    if out.shape[0] > 0:
        if m >= out.shape[0]:
            return -1
        out[m, 0], out[m, 1] = x, y
    return m + 1


@njit(cache=True, nogil=True)
def _emit_last(points: np.ndarray, out: np.ndarray, m: int, lx: float, ly: float, spacing: float) -> int:
    """Alg. 1's end: the last input point is appended when it lies more than ``spacing/2`` beyond
    the last emitted point ``(lx, ly)``."""
    n = points.shape[0]
    ex, ey = points[n - 1, 0] - lx, points[n - 1, 1] - ly
    if np.sqrt(ex * ex + ey * ey) > 0.5 * spacing:
        return _emit(out, m, points[n - 1, 0], points[n - 1, 1])
    return m


@njit(cache=True, nogil=True)
def _resample_into(points: np.ndarray, spacing: float, out: np.ndarray) -> int:
    """Algorithm 1 written into ``out``; returns the number of points, or -1 if ``out`` is too
    small (``out`` of shape ``(0, 2)`` just counts)."""
    n = points.shape[0]
    p1x, p1y = points[0, 0], points[0, 1]
    m = _emit(out, 0, p1x, p1y)
    i = 1
    surely_inside = spacing * spacing * (1.0 - 1e-9)   # d² below this ⇒ d ≤ spacing, no sqrt
    while i < n:
        dx, dy = points[i, 0] - p1x, points[i, 1] - p1y
        d2 = dx * dx + dy * dy
        if d2 < surely_inside:
            i += 1
            continue
        d = np.sqrt(d2)
        if d > spacing:
            p1x, p1y = p1x + dx / d * spacing, p1y + dy / d * spacing
            m = _emit(out, m, p1x, p1y)
            if m < 0:
                return -1
        else:
            i += 1
    return _emit_last(points, out, m, p1x, p1y, spacing)


@njit(cache=True, nogil=True)
def _resample_path_into(points: np.ndarray, spacing: float, out: np.ndarray) -> int:
    """Algorithm 1 read as Wolin et al.'s RESAMPLE-POINTS, written into ``out``: walk along the
    path through the input points ``(N, 2)`` and emit a point every ``spacing`` metres of path
    length, on the segment from P(i−1) to P(i) where that length is reached; the first input
    point always, the last one as :func:`resample` does. Returns the number of points, or -1 if
    ``out`` is too small (``out`` of shape ``(0, 2)`` just counts)."""
    n = points.shape[0]
    px, py = points[0, 0], points[0, 1]       # where the walk stands (last emitted or input point)
    lx, ly = px, py                           # last emitted point
    m = _emit(out, 0, px, py)
    walked = 0.0                              # path length since the last emitted point
    i = 1
    while i < n:
        dx, dy = points[i, 0] - px, points[i, 1] - py
        d = np.sqrt(dx * dx + dy * dy)
        if d > 0.0 and walked + d >= spacing:
            f = (spacing - walked) / d
            px, py = px + f * dx, py + f * dy
            lx, ly = px, py
            m = _emit(out, m, px, py)
            if m < 0:
                return -1
            walked = 0.0
        else:
            walked += d
            px, py = points[i, 0], points[i, 1]
            i += 1
    return _emit_last(points, out, m, lx, ly, spacing)


@njit(cache=True, nogil=True)
def _walk_into(points: np.ndarray, spacing: float, along_path: bool, out: np.ndarray) -> int:
    """:func:`_resample_path_into` if ``along_path``, else :func:`_resample_into`."""
    if along_path:
        return _resample_path_into(points, spacing, out)
    return _resample_into(points, spacing, out)


@njit(cache=True, nogil=True)
def walk_room(points: np.ndarray, spacing: float) -> int:
    """Room for Algorithm 1's walk of ``points`` ``(N, 2)`` at ``spacing`` metres, either walk:
    ``path length / spacing + 2N + 16`` points. The chord walk starts towards input point *i*
    from within S of point *i − 1* and steps S towards it while farther than S, so point *i*
    gives at most ``|P(i) − P(i−1)| / S + 1`` points; the path walk emits one per S of path; the
    first and last points add two. (The walks still check their room, and the callers count
    exactly and walk again should rounding ever exceed it.) A bound by the point count alone
    (``4N + 16``) holds a walk at ``tf``'s S = 1 m but not one at ``tf-plus``'s 5 cm (a 40 m scan
    path is 800 points for 181 beams), whose every walk would then count and walk again."""
    path = 0.0
    for i in range(1, points.shape[0]):
        dx, dy = points[i, 0] - points[i - 1, 0], points[i, 1] - points[i - 1, 1]
        path += np.sqrt(dx * dx + dy * dy)
    return int(path / spacing) + 2 * points.shape[0] + 16


@njit(cache=True, nogil=True)
def _walk(points: np.ndarray, spacing: float, along_path: bool) -> np.ndarray:
    """Algorithm 1's walk (chords, or along the path if ``along_path``) into an array sized from
    the path length (:func:`walk_room`): ``(M, 2)``."""
    n = points.shape[0]
    if n == 0:
        return np.empty((0, 2))
    out = np.empty((walk_room(points, spacing), 2))
    m = _walk_into(points, spacing, along_path, out)
    if m < 0:                  # longer than walk_room's bound (rounding): count exactly, redo
        out = np.empty((_walk_into(points, spacing, along_path, np.empty((0, 2))), 2))
        m = _walk_into(points, spacing, along_path, out)
    return out[:m]


@njit(cache=True, nogil=True)
def resample(points: np.ndarray, spacing: float) -> np.ndarray:
    """Algorithm 1: walk along ``points`` ``(N, 2)`` and emit points exactly ``spacing`` metres
    apart (chord length from the last emitted point towards the next input point).

    Returns ``(M, 2)``; the first input point is always kept, and the last input point is
    appended when it lies more than ``spacing/2`` beyond the last emitted point. As written,
    the walk follows chords, not the input path, so it cuts corners by up to ``spacing``.
    """
    return _walk(points, spacing, False)


@njit(cache=True, nogil=True)
def _median_into(values: np.ndarray, scratch: np.ndarray) -> float:
    """``np.median`` of a 1-D array (the mean of the two middle values when the size is even),
    sorting a copy in ``scratch`` (at least as long as ``values``)."""
    n = values.shape[0]
    v = scratch[:n]
    v[:] = values
    v.sort()
    h = n // 2
    if n % 2 == 1:
        return v[h]
    return (v[h - 1] + v[h]) / 2.0


@njit(cache=True, nogil=True)
def _candidates(points: np.ndarray, window: int, t: float) -> np.ndarray:
    """Algorithm 2 for ``len(points) > 2·window`` (see :func:`corner_candidates`)."""
    m = points.shape[0] - 2 * window
    out = np.empty(m + 2, dtype=np.int64)
    k = _candidates_into(points, window, t, np.empty(m), np.empty(m), out)
    return out[:k].copy()


@njit(cache=True, nogil=True)
def _candidates_into(points: np.ndarray, window: int, t: float, s: np.ndarray,
                     scratch: np.ndarray, out: np.ndarray) -> int:
    """:func:`_candidates` into ``out`` (``len(points) − 2·window + 2`` or more), with the
    straws in ``s`` and the median's sort in ``scratch`` (``len(points) − 2·window`` or more each);
    returns the number of candidates."""
    n = points.shape[0]
    m = n - 2 * window
    for i in range(m):
        dx = points[i + 2 * window, 0] - points[i, 0]
        dy = points[i + 2 * window, 1] - points[i, 1]
        s[i] = dx * dx + dy * dy
    cut = _median_into(s[:m], scratch) * t
    out[0] = 0
    k = 1
    for i in range(m):
        if s[i] < cut:
            out[k] = i + window
            k += 1
    out[k] = n - 1
    return k + 1


def corner_candidates(points: np.ndarray, window: int = 1, t: float = 0.99) -> np.ndarray:
    """Algorithm 2: indices of the first point, every point whose squared straw is below
    ``median × t``, and the last point (sorted, unique)."""
    n = len(points)
    if n <= 2 * window:
        return np.arange(n) if n < 2 else np.array([0, n - 1])
    return _candidates(np.asarray(points, dtype=float), int(window), float(t))


@njit(cache=True, nogil=True)
def _merge_lines_into(points: np.ndarray, corners: np.ndarray, threshold: float, cum: np.ndarray,
                      keep: np.ndarray) -> int:
    """Algorithm 3 applied to consecutive corner triples: drop the middle corner ``c_m`` whenever
    the path from ``c_l`` to ``c_n`` is a line, i.e. chord / path length > ``threshold``. One
    pass: the last kept corner, the pending middle corner and the next candidate form the triple;
    a dropped middle is replaced by the next candidate (the same triples, in the same order, as
    removing it from the list and testing again). The kept corners go into ``keep`` (as long as
    ``corners`` or more; at least 3 corners), the path lengths into ``cum`` (as long as
    ``points`` or more); returns the number kept."""
    n = points.shape[0]
    cum[0] = 0.0
    for i in range(1, n):
        dx, dy = points[i, 0] - points[i - 1, 0], points[i, 1] - points[i - 1, 1]
        cum[i] = cum[i - 1] + np.sqrt(dx * dx + dy * dy)
    k = corners.shape[0]
    keep[0] = corners[0]
    m = 1
    mid = corners[1]
    for j in range(2, k):
        a, b = keep[m - 1], corners[j]
        path = cum[b] - cum[a]
        dx, dy = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1]
        if not (path > 0.0 and np.sqrt(dx * dx + dy * dy) / path > threshold):
            keep[m] = mid
            m += 1
        mid = b
    keep[m] = mid
    return m + 1


@njit(cache=True, nogil=True)
def _shortstraw(points: np.ndarray, spacing: float, window: int, t: float,
                line_threshold: float, along_path: bool = False) -> np.ndarray:
    """Algs. 1–3 in one compiled call (see :func:`shortstraw`): :func:`_shortstraw_into` with
    buffers of its own, room for the walk as :func:`walk_room` bounds it and, should a walk ever
    be longer, exactly as many points as it has."""
    rows = walk_room(points, spacing)
    out = np.empty((rows + 2, 2))
    k = _shortstraw_into(points, spacing, window, t, line_threshold, along_path,
                         shortstraw_workspace(rows), out, 0)
    if k < 0:
        rows = _walk_into(points, spacing, along_path, np.empty((0, 2)))
        out = np.empty((rows + 2, 2))
        k = _shortstraw_into(points, spacing, window, t, line_threshold, along_path,
                             shortstraw_workspace(rows), out, 0)
    return out[:k].copy()


@njit(cache=True, nogil=True)
def shortstraw_workspace(rows: int) -> tuple:
    """Buffers for :func:`_shortstraw_into` on a walk (Alg. 1) of up to ``rows`` points: the
    walk ``(rows, 2)``, straws, sort scratch, candidates, path lengths, kept corners."""
    return (np.empty((rows, 2)), np.empty(rows), np.empty(rows), np.empty(rows + 2, dtype=np.int64),
            np.empty(rows), np.empty(rows + 2, dtype=np.int64))


@njit(cache=True, nogil=True)
def _shortstraw_into(points: np.ndarray, spacing: float, window: int, t: float,
                     line_threshold: float, along_path: bool, ws: tuple, out: np.ndarray,
                     offset: int) -> int:
    """Algs. 1–3 without allocations: the corners into rows ``offset …`` of ``out``
    (``offset + rows + 2`` rows or more), the work in ``ws`` (:func:`shortstraw_workspace` of
    ``rows`` walk points); returns the number of corners, or −1 when the walk does not fit
    in ``rows`` points (:func:`_shortstraw` then sizes the buffers for it)."""
    walk, straws, scratch, cand, cum, keep = ws
    if points.shape[0] == 0:
        return 0
    n = _walk_into(points, spacing, along_path, walk)
    if n < 0:
        return -1
    res = walk[:n]
    if n <= 2 * window:
        kc = n if n < 2 else 2
        if n < 2:
            for i in range(n):
                cand[i] = i
        else:
            cand[0], cand[1] = 0, n - 1
    else:
        kc = _candidates_into(res, window, t, straws, scratch, cand)
    if kc < 3:
        kk = kc
        for i in range(kc):
            keep[i] = cand[i]
    else:
        kk = _merge_lines_into(res, cand[:kc], line_threshold, cum, keep)
    for i in range(kk):
        out[offset + i, 0], out[offset + i, 1] = res[keep[i], 0], res[keep[i], 1]
    return kk


def shortstraw(points: np.ndarray, spacing: float, window: int = 1, t: float = 0.99,
               line_threshold: float = 0.95, along_path: bool = False) -> np.ndarray:
    """ShortStraw corners of an ordered polyline ``(N, 2)`` (metres) → corner points ``(K, 2)``.

    Alg. 1 (resample at ``spacing`` metres: chords, or along the path if ``along_path``), Alg. 2
    (straw candidates, ``window``, ``t``), Alg. 3 (Is-Line merging at ``line_threshold``). The
    first and last points are always corners.
    """
    pts = np.ascontiguousarray(points, dtype=float)
    if len(pts) < 2:
        return pts.copy()
    return _shortstraw(pts, float(spacing), int(window), float(t), float(line_threshold),
                       bool(along_path))
