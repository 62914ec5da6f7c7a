"""Compiled ray–segment kernels behind :meth:`VectorMap.raycast` (numba, one core).

:func:`raycast_segments` rasterises each segment onto the beams it can hit: from the pose, a
segment not passing through the sensor subtends an arc shorter than π, and only the beams whose
angles fall in that arc (plus a small safety margin) are intersected with it. The cost is
O(P·(M log M + B + hits)) instead of the brute force's O(P·B·M). The intersection arithmetic is the
brute force's, term for term, so both give the same ranges; :func:`raycast_segments_bruteforce`
is kept as the reference (tests compare them) and as the path for non-uniform beam angles.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .segment_index import candidates

_U_TOL = 1e-9          # hits within this fraction of a segment's length beyond its ends count
_ANGLE_MARGIN = 1e-4   # radians added on both sides of a segment's arc (≫ the error of _atan2)


@njit(cache=True, nogil=True)
def _atan2(y: float, x: float) -> float:
    """Approximate ``atan2(y, x)`` (error below 1e-5 rad; tests check it), for beam intervals
    only: ranges are always computed exactly."""
    ax, ay = abs(x), abs(y)
    mx, mn = max(ax, ay), min(ax, ay)
    if mx == 0.0:
        return 0.0
    a = mn / mx
    s = a * a
    r = (((((-0.013480470 * s + 0.057477314) * s - 0.121239071) * s + 0.195635925) * s
          - 0.332994597) * s + 0.999995630) * a
    if ay > ax:
        r = 0.5 * np.pi - r
    if x < 0.0:
        r = np.pi - r
    return -r if y < 0.0 else r


@njit(cache=True, nogil=True)
def _near_segments(ox: float, oy: float, segs: np.ndarray, max_range: float,
                   near: np.ndarray, dist: np.ndarray, index: tuple, seen: np.ndarray,
                   stamp: int) -> int:
    """Indices (into ``near``) and distances (``dist``) of the segments closer than ``max_range``
    to ``(ox, oy)``; returns their count. With a segment ``index``
    (:mod:`tfloc.maps.segment_index`; ``nx`` > 0) only the segments of the cells within range
    are tested (``seen``/``stamp``: see :func:`~tfloc.maps.segment_index.candidates`), else all:
    the same segments either way, in another order."""
    if index[3] > 0:
        n_c = candidates(index, ox, oy, max_range, seen, stamp, near)
    else:
        n_c = segs.shape[0]
    k = 0
    for c in range(n_c):
        m = near[c] if index[3] > 0 else c
        ax, ay = segs[m, 0] - ox, segs[m, 1] - oy
        ex, ey = segs[m, 2] - segs[m, 0], segs[m, 3] - segs[m, 1]
        ll = ex * ex + ey * ey
        u = 0.0
        if ll > 0.0:
            u = -(ax * ex + ay * ey) / ll
            u = min(1.0, max(0.0, u))
        cx, cy = ax + u * ex, ay + u * ey
        d2 = cx * cx + cy * cy
        if d2 < max_range * max_range:
            near[k] = m
            dist[k] = np.sqrt(d2)
            k += 1
    return k


@njit(cache=True, nogil=True)
def _hit(ox: float, oy: float, dx: float, dy: float, seg: np.ndarray, best: float) -> float:
    """Range along the unit ray ``(dx, dy)`` from ``(ox, oy)`` to ``seg`` if below ``best``,
    else ``best`` (the brute force's test, unchanged)."""
    wx, wy = seg[0] - ox, seg[1] - oy
    ex, ey = seg[2] - seg[0], seg[3] - seg[1]
    den = dx * ey - dy * ex
    if abs(den) < 1e-12:
        return best
    t = (wx * ey - wy * ex) / den
    if t < 0.0 or t >= best:
        return best
    u = (wx * dy - wy * dx) / den
    if -_U_TOL <= u <= 1.0 + _U_TOL:
        return t
    return best


@njit(cache=True, fastmath=False, nogil=True)
def raycast_segments_bruteforce(poses: np.ndarray, rel_angles: np.ndarray, segs: np.ndarray,
                                max_range: float, index: tuple) -> np.ndarray:
    """Reference kernel: every beam against every nearby segment, O(P·(M + B·M_near)).

    Same contract as :func:`raycast_segments`; works for any beam angles.
    """
    P = poses.shape[0]
    B = rel_angles.shape[0]
    M = segs.shape[0]
    out = np.full((P, B), np.inf)
    near = np.empty(M, dtype=np.int64)
    dist = np.empty(M)
    seen = np.zeros(M if index[3] > 0 else 0, dtype=np.int64)
    for p in range(P):
        ox, oy, th = poses[p, 0], poses[p, 1], poses[p, 2]
        k = _near_segments(ox, oy, segs, max_range, near, dist, index, seen, p + 1)
        for b in range(B):
            a = th + rel_angles[b]
            dx, dy = np.cos(a), np.sin(a)
            best = max_range
            for j in range(k):
                best = _hit(ox, oy, dx, dy, segs[near[j]], best)
            if best < max_range:
                out[p, b] = best
    return out


@njit(cache=True, nogil=True)
def _uniform_spacing(rel_angles: np.ndarray) -> tuple[float, float, float]:
    """``(angle_min, resolution, max deviation)`` of the best uniform fit ``a0 + i·res``;
    resolution 0 when fewer than 2 beams or not increasing."""
    B = rel_angles.shape[0]
    if B < 2:
        return 0.0, 0.0, 0.0
    a0 = rel_angles[0]
    res = (rel_angles[B - 1] - a0) / (B - 1)
    if not res > 0.0:
        return a0, 0.0, 0.0
    dev = 0.0
    for i in range(B):
        dev = max(dev, abs(rel_angles[i] - (a0 + i * res)))
    return a0, res, dev


_ORDER_BINS = 32  # distance bins of the segments' near-first order (speed only)


@njit(cache=True, nogil=True)
def _near_first(dist: np.ndarray, k: int, max_range: float) -> np.ndarray:
    """An order of the first ``k`` segments that is near first to within ``max_range / 32``
    (a counting sort by distance bin; in a bin, in index order).

    The ranges do not depend on the order the segments are visited in: a beam's range is the
    least hit over all segments, and a segment is skipped for a beam only where the beam's
    nearest hit so far provably lies before it. Visiting near segments first only makes the
    skips frequent; a counting sort, because a full ``np.argsort`` cost about a third of a ray
    cast from a new position (``docs/speed.md``)."""
    counts = np.zeros(_ORDER_BINS + 1, dtype=np.int64)
    scale = _ORDER_BINS / max_range
    for j in range(k):
        counts[min(int(dist[j] * scale), _ORDER_BINS - 1) + 1] += 1
    for b in range(_ORDER_BINS):
        counts[b + 1] += counts[b]
    out = np.empty(k, dtype=np.int64)
    for j in range(k):
        b = min(int(dist[j] * scale), _ORDER_BINS - 1)
        out[counts[b]] = j
        counts[b] += 1
    return out


@njit(cache=True, nogil=True)
def _arcs(ox: float, oy: float, segs: np.ndarray, max_range: float, dev: float,
          near: np.ndarray, dist: np.ndarray, seg_of: np.ndarray, every: np.ndarray,
          start: np.ndarray, width: np.ndarray, margin: np.ndarray, h_safe: np.ndarray,
          den_min: np.ndarray, ex: np.ndarray, ey: np.ndarray, index: tuple, seen: np.ndarray,
          stamp: int) -> int:
    """What :func:`raycast_segments` needs of the segments seen from ``(ox, oy)``, independent of
    the heading: the segments within ``max_range``, near first (``seg_of``, :func:`_near_first`), whether each must
    be tested against every beam (``every``), else the arc it subtends (``start``, ``width``,
    ``margin``) and its occlusion test (``h_safe``, ``den_min``, ``ex``, ``ey``); returns their count."""
    two_pi = 2.0 * np.pi
    k = _near_segments(ox, oy, segs, max_range, near, dist, index, seen, stamp)
    order = _near_first(dist, k, max_range)
    for jj in range(k):
        j = order[jj]
        m = near[j]
        seg_of[jj] = m
        seg = segs[m]
        ax, ay = seg[0] - ox, seg[1] - oy
        bx, by = seg[2] - ox, seg[3] - oy
        length = np.sqrt((bx - ax) ** 2 + (by - ay) ** 2)
        slack = 2.0 * _U_TOL * length     # how far beyond an end a counted hit can lie
        h = dist[j]
        if h <= 1e3 * slack or h < 1e-9:  # through (or at) the sensor: every beam
            every[jj] = True
            continue
        # arc [start, start + width] (relative to the first beam) the segment subtends
        alpha = _atan2(ay, ax)
        beta = _atan2(by, bx)
        d = beta - alpha
        d = d - two_pi * np.floor((d + np.pi) / two_pi)   # in [-π, π)
        if abs(d) > np.pi - 1e-3:         # nearly through the sensor: every beam
            every[jj] = True
            continue
        every[jj] = False
        # A beam hit (within the u tolerance) lies ≥ h − slack away; with |den| ≥ den_min the
        # computed t is within 1e-9 (relative) of the true one, so a beam whose nearest hit
        # so far is below h_safe cannot be hit here (whatever the order segments are visited in).
        ex[jj], ey[jj] = bx - ax, by - ay
        h_safe[jj] = (h - slack) * (1.0 - 1e-9)
        den_min[jj] = 1e-5 * length * (1.0 + length / h)
        start[jj] = alpha if d >= 0.0 else beta
        width[jj] = abs(d)
        margin[jj] = _ANGLE_MARGIN + dev + 2.0 * slack / (h - slack)
    return k


_SWEEP = 8  # poses at one position whose beam directions a later pose there may reuse


@njit(cache=True, nogil=True)
def _directions(th: float, rel_angles: np.ndarray, res: float, headings: np.ndarray, group: int,
                p: int, shift: np.ndarray, angle: np.ndarray, dx_of: np.ndarray,
                dy_of: np.ndarray, src_pose: np.ndarray, src_beam: np.ndarray) -> None:
    """Beam ``b``'s angle ``th + rel_angles[b]`` of pose ``p`` and its direction (cos, sin) into
    row ``(p − group) mod _SWEEP`` of ``angle``, ``dx_of``, ``dy_of``.

    Poses ``group … p−1`` stand at the same position (a heading sweep, e.g. Alg. 5's seven
    orientations one beam apart). Where pose ``p``'s heading lies a whole number of beams ``s``
    from that of one of the last ``_SWEEP − 1`` of them, pose ``j`` (``shift``), its beam ``b``
    is often *exactly* (to the last bit) pose ``j``'s beam ``b + s``, and then its cos and sin are
    copied from there instead of computed again: the same values (the same libm call on the
    same number gave them). In a seven-heading sweep about two thirds of the angles repeat.
    The source of beam ``b`` goes to ``src_pose[b]``, ``src_beam[b]`` (−1: computed here): the
    same origin and the same direction to the last bit, so the same range."""
    B = rel_angles.shape[0]
    first = max(group, p - _SWEEP + 1)
    for j in range(first, p):
        q = (th - headings[j]) / res
        s = np.floor(q + 0.5)
        ok = abs(q - s) < 1e-6 and abs(s) < B
        shift[(j - group) % _SWEEP] = np.int64(s) if ok else B  # B: no candidate beam
    row = (p - group) % _SWEEP
    for b in range(B):
        a = th + rel_angles[b]
        angle[row, b] = a
        src_pose[b] = -1
        for j in range(p - 1, first - 1, -1):
            r = (j - group) % _SWEEP
            c = b + shift[r]
            if 0 <= c < B and angle[r, c] == a:
                dx_of[row, b], dy_of[row, b] = dx_of[r, c], dy_of[r, c]
                src_pose[b], src_beam[b] = j, c
                break
        if src_pose[b] < 0:
            dx_of[row, b], dy_of[row, b] = np.cos(a), np.sin(a)


@njit(cache=True, fastmath=False, nogil=True)
def raycast_segments(poses: np.ndarray, rel_angles: np.ndarray, segs: np.ndarray,
                     max_range: float, index: tuple) -> np.ndarray:
    """Ranges from each pose ``(P, 3)`` along each beam ``(B,)`` to the nearest of ``segs``
    ``(M, 4)`` = (ax, ay, bx, by). No hit before ``max_range`` gives ``inf``. Metres, radians.

    ``index``: the map's segment buckets (:func:`tfloc.maps.segment_index.build_index`, or
    :data:`~tfloc.maps.segment_index.NO_INDEX` to test every segment for range).
    ``rel_angles`` (relative to each pose's heading) should be uniformly spaced and increasing,
    as a :class:`~tfloc.core.laser.LaserSpec` gives them; otherwise (deviation above 1e-6 rad) the
    brute-force kernel is used. Segments farther than ``max_range`` are culled; each remaining
    segment is intersected only with the beams inside the arc it subtends (wrap-around of
    360° scanners included). A segment within rounding distance of the sensor is intersected
    with every beam, so the answer never depends on the arc computation. Segments are visited
    nearest first (by distance bins, :func:`_near_first`), and a beam whose hit so far is nearer than a segment's distance skips it
    (only when the skip provably agrees with the brute force's test). Consecutive poses at the
    same position (e.g. several headings) share the heading-independent work (:func:`_arcs`),
    and a ray that one of them already cast (the same direction to the last bit,
    :func:`_directions`) is not cast again.
    """
    P = poses.shape[0]
    B = rel_angles.shape[0]
    M = segs.shape[0]
    a0, res, dev = _uniform_spacing(rel_angles)
    if res == 0.0 or dev > 1e-6:
        return raycast_segments_bruteforce(poses, rel_angles, segs, max_range, index)
    two_pi = 2.0 * np.pi
    out = np.full((P, B), np.inf)
    best = np.empty(B)
    angle = np.empty((_SWEEP, B))     # the beam angles and directions of the last poses
    dx_of = np.empty((_SWEEP, B))     # at this position (rows: pose − group, mod _SWEEP)
    dy_of = np.empty((_SWEEP, B))
    shift = np.zeros(_SWEEP, dtype=np.int64)
    src_pose = np.empty(B, dtype=np.int64)  # a beam's ray cast before: pose, beam (else −1)
    src_beam = np.empty(B, dtype=np.int64)
    next_cast = np.empty(B + 1, dtype=np.int64)  # the first beam ≥ b not cast before (B: none)
    group = 0                         # the first pose at the current position
    near = np.empty(M, dtype=np.int64)
    dist = np.empty(M)
    seg_of = np.empty(M, dtype=np.int64)
    every = np.empty(M, dtype=np.bool_)
    start = np.empty(M)
    width = np.empty(M)
    margin = np.empty(M)
    h_safe = np.empty(M)
    den_min = np.empty(M)
    ex = np.empty(M)
    ey = np.empty(M)
    seen = np.zeros(M if index[3] > 0 else 0, dtype=np.int64)
    k = 0
    wrap_up = two_pi / res <= B - 1.0   # can an arc one turn up reach a beam (360° scanners)?
    for p in range(P):
        ox, oy, th = poses[p, 0], poses[p, 1], poses[p, 2]
        moved = p == 0 or ox != poses[p - 1, 0] or oy != poses[p - 1, 1]
        if moved:
            group = p
        _directions(th, rel_angles, res, poses[:, 2], group, p, shift, angle, dx_of, dy_of,
                    src_pose, src_beam)
        dxs, dys = dx_of[(p - group) % _SWEEP], dy_of[(p - group) % _SWEEP]
        next_cast[B] = B            # a ray cast before is not cast again: the beam loops
        for b in range(B - 1, -1, -1):  # below step from one beam to cast to the next
            best[b] = max_range
            next_cast[b] = b if src_pose[b] < 0 else next_cast[b + 1]
        if moved:
            k = _arcs(ox, oy, segs, max_range, dev, near, dist, seg_of, every, start, width,
                      margin, h_safe, den_min, ex, ey, index, seen, p + 1)
        for jj in range(k):
            seg = segs[seg_of[jj]]
            if every[jj]:
                b = next_cast[0]
                while b < B:
                    best[b] = _hit(ox, oy, dxs[b], dys[b], seg, best[b])
                    b = next_cast[b + 1]
                continue
            rel = start[jj] - th - a0 - margin[jj]
            rel = rel - two_pi * np.floor(rel / two_pi)        # in [0, 2π)
            top = rel + width[jj] + 2.0 * margin[jj]
            for wrap in range(-1, 2):                          # beams i·res ≡ arc (mod 2π)
                if (wrap == -1 and top < two_pi) or (wrap == 1 and not wrap_up):
                    continue                                   # (the tests below would skip it)
                lo_f = np.ceil((rel + wrap * two_pi) / res)
                hi_f = np.floor((top + wrap * two_pi) / res)
                if hi_f < 0.0 or lo_f > B - 1.0:
                    continue
                lo, hi = int(max(lo_f, 0.0)), int(min(hi_f, B - 1.0))
                b = next_cast[lo]
                while b <= hi:
                    # occluded: t ≥ h > best, unless t is ill-conditioned
                    if not (best[b] <= h_safe[jj]
                            and abs(dxs[b] * ey[jj] - dys[b] * ex[jj]) >= den_min[jj]):
                        best[b] = _hit(ox, oy, dxs[b], dys[b], seg, best[b])
                    b = next_cast[b + 1]
        for b in range(B):
            if src_pose[b] >= 0:
                out[p, b] = out[src_pose[b], src_beam[b]]
            elif best[b] < max_range:
                out[p, b] = best[b]
    return out
