"""The selection cost of ``tf-plus`` (:mod:`tfloc.tfplus.cost`) in one compiled call per map kind.

Per beam of the real scan at each candidate pose: the truncated point-to-line residual to the
map's nearest points (:func:`residual_pen_kernel`), ``c²`` where the map says the beam cannot be
(see-through: on a vector map against the ray-cast range, :func:`vector_see_through_kernel`; on a
grid map beyond the far side of the first wall, :func:`see_through_kernel`), and the mean over
the beams as numpy takes it (:func:`tfloc.paper.turning._pairwise_sum`). The same values as
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
                       beam_check: bool) -> np.ndarray:
    """The selection cost ``(K,)`` (metres²) at ``poses`` ``(K, 3)`` on a vector map (segments
    ``segs``, their buckets ``index``): see the module docstring."""
    pen = residual_pen_kernel(nearest, origin_x, origin_y, resolution, map_points, map_normals,
                              ranges, directions, max_range, poses, c)
    if beam_check:
        virtual = raycast_segments(poses, angles, segs, max_range, index)
        vector_see_through_kernel(pen, ranges, virtual, max_range, c)
    return _row_means(pen)


@njit(cache=True, nogil=True)
def grid_cost_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                     map_points: np.ndarray, map_normals: np.ndarray, ranges: np.ndarray,
                     directions: np.ndarray, angles: np.ndarray, max_range: float,
                     poses: np.ndarray, occupied: np.ndarray, grid_x: float, grid_y: float,
                     cell: float, c: float, beam_check: bool) -> np.ndarray:
    """The selection cost ``(K,)`` (metres²) at ``poses`` ``(K, 3)`` on a grid map (``occupied``
    cells of ``cell`` metres from ``(grid_x, grid_y)``): see the module docstring."""
    pen = residual_pen_kernel(nearest, origin_x, origin_y, resolution, map_points, map_normals,
                              ranges, directions, max_range, poses, c)
    if beam_check:
        see = see_through_kernel(occupied, grid_x, grid_y, cell, poses, angles, ranges,
                                 max_range, c)
        for k in range(pen.shape[0]):
            for b in range(pen.shape[1]):
                if see[k, b]:
                    pen[k, b] = c * c
    return _row_means(pen)
