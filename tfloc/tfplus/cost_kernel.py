"""The selection cost of ``tf-plus`` (:mod:`tfloc.tfplus.cost`) in one compiled call per map kind.

Per beam of the real scan at each candidate pose: the truncated point-to-line residual to the
map's nearest points (:func:`residual_pen_kernel`), at most ``short²`` for the returns of a group
the map says is clear of walls beyond it (:func:`vector_short_mask`, :func:`beam_flags_kernel`,
:func:`unmapped_kernel`), ``c²``
where the map says the beam cannot be (see-through: on a vector map against the ray-cast range,
:func:`vector_see_through_kernel`; on a grid map beyond the far side of the first wall,
:func:`see_through_kernel`), bounded to a share of the beams (:func:`bounded_see_through`), and
the mean over the beams as numpy takes it (:func:`tfloc.paper.turning._pairwise_sum`). The same values as
:func:`tfloc.tfplus.cost.scan_cost_steps`, element by element; from Python the steps were a
dozen numpy calls, each costing more than its arithmetic.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from tfloc.maps._gridcast import _entry, _start, _step
from tfloc.maps._raycast import raycast_segments
from tfloc.paper.turning import _pairwise_sum

from .field_kernel import _to_nearest


@njit(cache=True, nogil=True)
def _returned(r: float, max_range: float) -> bool:
    """Whether a range is a return (finite, > 0, < ``max_range``), as ``LaserSpec.valid``."""
    return np.isfinite(r) and r > 0.0 and r < max_range


@njit(cache=True, nogil=True)
def _first_wall(occ: np.ndarray, x0: float, y0: float, dx: float, dy: float, t0: float,
                t1: float, through: bool, deep: float) -> tuple[float, float]:
    """The one grid walk of the beam checks: the unit ray (cell units) from its cell at parameter
    ``t0`` (inside the grid) through the cells it enters by ``t1``. Returns the parameters at
    which it enters the first occupied cell of ``occ`` and the first free cell after that run
    (each ``inf``: none). The walk stops at the first occupied cell unless ``through``, and at
    any occupied cell entered beyond ``deep`` (what lies after it is not asked)."""
    H, W = occ.shape
    i, j, sx, sy, tdx, tdy, tx, ty = _start(x0, y0, dx, dy, t0, W, H)
    t = t0
    enter = np.inf
    while t <= t1:
        if occ[j, i]:
            if enter == np.inf:
                enter = t
            if not through or t > deep:
                return enter, np.inf
        elif enter < np.inf:
            return enter, t
        t = min(tx, ty)
        i, j, tx, ty, inside_grid = _step(i, j, sx, sy, tdx, tdy, tx, ty, W, H)
        if not inside_grid:
            break
    return enter, np.inf


@njit(cache=True, nogil=True)
def see_through_kernel(occ: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       poses: np.ndarray, angles: np.ndarray, ranges: np.ndarray,
                       max_range: float, margin: float) -> np.ndarray:
    """Which beams ``(K, n)`` of the real scan ``ranges`` ``(n,)`` (metres, ``angles`` relative to
    the sensor) the occupied grid ``occ`` says cannot be, at each of ``(K, 3)`` poses: a return
    more than ``margin`` beyond the far side of the first wall the beam meets (where the first
    run of occupied cells ends: a wall drawn several cells thick holds returns anywhere inside it),
    or no return (NaN, inf, ≥ ``max_range``) where the beam meets a wall within ``max_range``.
    Each beam is followed only as far as it needs to be (:func:`_first_wall`, the walk
    :func:`beam_flags_kernel` takes too). Its loop over the beams stays apart from
    :func:`beam_flags_kernel`'s, which gives the same beams, because it is the default
    selection's hot path, where the general kernel measured 3–4 % slower per call."""
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
            enter, leave = _first_wall(occ, x0, y0, dx, dy, t0, min(t1, limit), ret, np.inf)
            # no return: any wall; a return: it left the first wall before the return
            out[k, b] = leave < np.inf if ret else enter < np.inf
    return out


@njit(cache=True, nogil=True)
def beam_flags_kernel(occ: np.ndarray, free: np.ndarray, origin_x: float, origin_y: float,
                      resolution: float, poses: np.ndarray, angles: np.ndarray, ranges: np.ndarray,
                      max_range: float, margin: float, short_margin: float, with_see: bool,
                      wanted: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`see_through_kernel`'s beams ``(K, n)`` (``margin``; with ``with_see``, else none),
    the same values, and in the same walk the **short** ones ``(K, n)`` among the ``wanted``
    ``(n,)``: a return whose cell is known ``free`` and whose ray meets no occupied cell up to
    ``short_margin`` beyond it (the map expects the beam to go on: an object the map lacks
    stopped it). Each beam is followed only as far as it needs to be; the stretch beyond a
    return is looked at first (most returns lie on a wall)."""
    H, W = occ.shape
    k_n, n = poses.shape[0], angles.shape[0]
    see = np.zeros((k_n, n), dtype=np.bool_)
    short = np.zeros((k_n, n), dtype=np.bool_)
    for k in range(k_n):
        x0, y0 = (poses[k, 0] - origin_x) / resolution, (poses[k, 1] - origin_y) / resolution
        for b in range(n):
            r = ranges[b]
            ret = r > 0.0 and r < max_range            # False for NaN
            near = (r - margin) / resolution if ret else max_range / resolution
            check = with_see and near > 0.0             # see_through_kernel's beams to follow
            if not (check or (ret and wanted[b])):
                continue
            a = poses[k, 2] + angles[b]
            dx, dy = math.cos(a), math.sin(a)
            clear = False
            if ret and wanted[b]:
                ex, ey = math.floor(x0 + dx * (r / resolution)), math.floor(y0 + dy * (r / resolution))
                clear = (0.0 <= ex < W and 0.0 <= ey < H and free[int(ey), int(ex)]
                         and _first_wall(occ, x0, y0, dx, dy, r / resolution,
                                         (r + short_margin) / resolution, False, np.inf)[0] == np.inf)
            if not (check or clear):
                continue
            t0, t1 = _entry(x0, y0, dx, dy, W, H)
            far = (r + short_margin) / resolution if clear else near
            if t0 > t1 or t0 > far:
                short[k, b] = clear
                continue
            # far ≥ near if clear, = near if not; past near only the short test asks (a wall)
            enter, leave = _first_wall(occ, x0, y0, dx, dy, t0, min(t1, far), ret,
                                       near if check else -np.inf)
            if enter < np.inf:
                clear = False
                see[k, b] = check and enter <= near and (not ret or leave <= near)
            short[k, b] = clear
    return see, short


@njit(cache=True, nogil=True)
def residual_pen_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                        map_points: np.ndarray, map_normals: np.ndarray, ranges: np.ndarray,
                        directions: np.ndarray, max_range: float, poses: np.ndarray,
                        c: float) -> np.ndarray:
    """The point-to-line part of ``tf-plus``'s selection cost (:mod:`tfloc.tfplus.cost`), per
    beam ``(K, n)`` (metres²): each return's ranking residual to the nearest map point of its
    cell (:func:`~tfloc.tfplus.field_kernel.field_pairs_kernel`'s, with the cell size as
    slack) truncated at ``c``, squared; 0 for a beam with no return. The same arithmetic as the
    numpy steps it replaces (the scan points of :meth:`LaserSpec.to_points`, the ranking
    residual, ``min(r, c)²``)."""
    k_n, n = poses.shape[0], ranges.shape[0]
    out = np.zeros((k_n, n))
    field = (nearest, origin_x, origin_y, 1.0 / resolution, map_points)
    for k in range(k_n):
        px, py = poses[k, 0], poses[k, 1]
        cs, sn = math.cos(poses[k, 2]), math.sin(poses[k, 2])
        for b in range(n):
            r = ranges[b]
            if not _returned(r, max_range):
                continue
            x, y = directions[b, 0] * r, directions[b, 1] * r
            _, _, j, dx, dy = _to_nearest(field, px, py, cs, sn, x, y)
            if j < 0:
                out[k, b] = c * c
                continue
            res = map_normals[j, 0] * dx + map_normals[j, 1] * dy
            rank = max(abs(res), math.sqrt(dx * dx + dy * dy) - resolution)
            t = min(rank, c)
            out[k, b] = t * t
    return out


@njit(cache=True, nogil=True)
def vector_see_through_kernel(pen: np.ndarray, ranges: np.ndarray, virtual: np.ndarray,
                              max_range: float, c: float) -> None:
    """Set ``pen`` ``(K, n)`` to ``c²`` at the beams a vector map says cannot be, given its
    virtual scans ``(K, n)``: the map has a wall within range and the real return lies more than
    ``c`` beyond it, or there is none (:func:`tfloc.tfplus.cost.see_through`)."""
    for k in range(pen.shape[0]):
        for b in range(pen.shape[1]):
            v = virtual[k, b]
            if not _returned(v, max_range):
                continue
            r = ranges[b]
            if not _returned(r, max_range) or r > v + c:
                pen[k, b] = c * c


@njit(cache=True, nogil=True)
def object_groups_kernel(ranges: np.ndarray, directions: np.ndarray, max_range: float,
                         spacing: float, max_extent: float) -> np.ndarray:
    """The scan ``ranges`` (metres) cut into groups ``(n,)`` (a label per beam, -1: none): runs
    of consecutive returns, each within 0.1 m + two beam spacings (``spacing``, radians) at its
    range of the previous one, whose first and last points lie at most ``max_extent`` metres
    apart (a person, a box, a cart). A longer run is a wall and gets -1; ``max_extent`` < 0:
    every return a group of its own. Depends on the scan alone."""
    n = ranges.shape[0]
    out = np.full(n, -1, dtype=np.int64)
    b = 0
    while b < n:
        if not _returned(ranges[b], max_range):
            b += 1
            continue
        e = b
        while max_extent >= 0.0 and e + 1 < n and _returned(ranges[e + 1], max_range):
            r0, r1 = ranges[e], ranges[e + 1]
            dx = directions[e + 1, 0] * r1 - directions[e, 0] * r0
            dy = directions[e + 1, 1] * r1 - directions[e, 1] * r0
            if math.sqrt(dx * dx + dy * dy) > 0.1 + 2.0 * spacing * min(r0, r1):
                break
            e += 1
        dx = directions[e, 0] * ranges[e] - directions[b, 0] * ranges[b]
        dy = directions[e, 1] * ranges[e] - directions[b, 1] * ranges[b]
        if max_extent < 0.0 or math.sqrt(dx * dx + dy * dy) <= max_extent:
            for i in range(b, e + 1):
                out[i] = b
        b = e + 1
    return out


@njit(cache=True, nogil=True)
def unmapped_kernel(short: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """The returns ``(K, n)`` of the groups ``(n,)`` (:func:`object_groups_kernel`) that are
    short ``(K, n)`` as a whole at each pose: an object the map lacks."""
    k_n, n = short.shape
    out = np.zeros((k_n, n), dtype=np.bool_)
    for k in range(k_n):
        b = 0
        while b < n:
            g = groups[b]
            if g < 0:
                b += 1
                continue
            e, whole = b, True
            while e < n and groups[e] == g:
                whole = whole and short[k, e]
                e += 1
            for i in range(b, e):
                out[k, i] = whole
            b = e
    return out


@njit(cache=True, nogil=True)
def _cap(pen: np.ndarray, mask: np.ndarray, value: float) -> None:
    """``pen = min(pen, value)`` where ``mask`` (in place)."""
    for k in range(pen.shape[0]):
        for b in range(pen.shape[1]):
            if mask[k, b]:
                pen[k, b] = min(pen[k, b], value)


@njit(cache=True, nogil=True)
def vector_see_through_mask(ranges: np.ndarray, virtual: np.ndarray, max_range: float,
                            c: float) -> np.ndarray:
    """The beams ``(K, n)`` :func:`vector_see_through_kernel` sets to ``c²``."""
    out = np.zeros(virtual.shape, dtype=np.bool_)
    for k in range(virtual.shape[0]):
        for b in range(virtual.shape[1]):
            v = virtual[k, b]
            if _returned(v, max_range):
                r = ranges[b]
                out[k, b] = not _returned(r, max_range) or r > v + c
    return out


@njit(cache=True, nogil=True)
def vector_short_mask(ranges: np.ndarray, virtual: np.ndarray, max_range: float,
                      margin: float) -> np.ndarray:
    """The **short** returns ``(K, n)`` on a vector map: the virtual scan ``(K, n)`` has no wall
    within range, or its wall lies more than ``margin`` beyond the return
    (:func:`tfloc.tfplus.cost.short_beams`)."""
    out = np.zeros(virtual.shape, dtype=np.bool_)
    for k in range(virtual.shape[0]):
        for b in range(virtual.shape[1]):
            r = ranges[b]
            if _returned(r, max_range):
                v = virtual[k, b]
                out[k, b] = not _returned(v, max_range) or r < v - margin
    return out


@njit(cache=True, nogil=True)
def bounded_see_through(pen: np.ndarray, see: np.ndarray, c: float, share: float) -> None:
    """Set ``pen`` ``(K, n)`` to ``c²`` at the see-through beams ``see`` of each pose while they
    are at most ``share`` of the beams; beyond that, move each one's penalty towards ``c²`` by
    ``share · n / count``, so that together they add what ``share · n`` beams in full would add
    to a pose whose residuals are zero (:func:`tfloc.tfplus.cost.bound_see_through`)."""
    n = pen.shape[1]
    c2 = c * c
    cap = share * n
    for k in range(pen.shape[0]):
        m = 0
        for b in range(n):
            m += see[k, b]
        if m == 0:
            continue
        scale = cap / m
        for b in range(n):
            if see[k, b]:
                pen[k, b] = c2 if m <= cap else pen[k, b] + scale * (c2 - pen[k, b])


@njit(cache=True, nogil=True)
def _row_means(pen: np.ndarray) -> np.ndarray:
    """``pen.mean(axis=1)`` bit for bit."""
    out = np.empty(pen.shape[0])
    for k in range(pen.shape[0]):
        out[k] = _pairwise_sum(pen[k]) / pen.shape[1]
    return out


@njit(cache=True, nogil=True)
def vector_cost_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       map_points: np.ndarray, map_normals: np.ndarray, ranges: np.ndarray,
                       directions: np.ndarray, angles: np.ndarray, max_range: float,
                       poses: np.ndarray, segs: np.ndarray, index: tuple, c: float,
                       beam_check: bool, short: float, share: float, short_margin: float,
                       groups: np.ndarray) -> np.ndarray:
    """The selection cost ``(K,)`` (metres²) at ``poses`` ``(K, 3)`` on a vector map (segments
    ``segs``, their buckets ``index``): see the module docstring (``short`` < 0: no short
    term; ``groups`` ``(n,)``: :func:`object_groups_kernel`'s)."""
    pen = residual_pen_kernel(nearest, origin_x, origin_y, resolution, map_points, map_normals,
                              ranges, directions, max_range, poses, c)
    if beam_check or short >= 0.0:
        virtual = raycast_segments(poses, angles, segs, max_range, index)
        if short >= 0.0:
            _cap(pen, unmapped_kernel(vector_short_mask(ranges, virtual, max_range, short_margin),
                                      groups), short * short)
        if beam_check and share >= 1.0:
            vector_see_through_kernel(pen, ranges, virtual, max_range, c)
        elif beam_check:
            bounded_see_through(pen, vector_see_through_mask(ranges, virtual, max_range, c), c,
                                share)
    return _row_means(pen)


@njit(cache=True, nogil=True)
def grid_cost_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                     map_points: np.ndarray, map_normals: np.ndarray, ranges: np.ndarray,
                     directions: np.ndarray, angles: np.ndarray, max_range: float,
                     poses: np.ndarray, occupied: np.ndarray, grid_x: float, grid_y: float,
                     cell: float, c: float, beam_check: bool, free: np.ndarray, short: float,
                     share: float, short_margin: float, groups: np.ndarray) -> np.ndarray:
    """The selection cost ``(K,)`` (metres²) at ``poses`` ``(K, 3)`` on a grid map (``occupied``
    and ``free`` cells of ``cell`` metres from ``(grid_x, grid_y)``): see the module docstring
    (``short`` < 0: no short term)."""
    pen = residual_pen_kernel(nearest, origin_x, origin_y, resolution, map_points, map_normals,
                              ranges, directions, max_range, poses, c)
    if short >= 0.0 or share < 1.0:
        see, near = beam_flags_kernel(occupied, free, grid_x, grid_y, cell, poses, angles, ranges,
                                      max_range, c, short_margin, beam_check, groups >= 0)
        if short >= 0.0:
            _cap(pen, unmapped_kernel(near, groups), short * short)
        if beam_check:
            bounded_see_through(pen, see, c, share)
    elif beam_check:
        see = see_through_kernel(occupied, grid_x, grid_y, cell, poses, angles, ranges,
                                 max_range, c)
        for k in range(pen.shape[0]):
            for b in range(pen.shape[1]):
                if see[k, b]:
                    pen[k, b] = c * c
    return _row_means(pen)
