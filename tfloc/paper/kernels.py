"""The ``tf`` cost evaluation after the virtual scan, fused into one compiled call per batch.

One call takes the virtual scans of a batch of poses (the seven orientations of Alg. 5's
Function1) and returns Err and the rotation offset for each: ranges → points (Eq. 4) →
ShortStraw corners (Algs. 1–3) → closed scan polygon → turning function (Alg. 4) → matching
against the real scan's turning function (Sec. 4.3 / Eq. 13). It runs exactly the compiled
kernels that the step-by-step path (:func:`tfloc.paper.shape.scan_turning_function`, :func:`tfloc.paper.turning.match`)
calls one by one from Python, in the same order with the same arithmetic, so both give identical
results (tests/paper/test_perf_tf_equivalence.py); only the Python overhead per pose is gone.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from tfloc.core.laser import _returns_to_points, _returns_to_points_into
from tfloc.maps._raycast import raycast_segments
from tfloc.maps.inside import raster_code

from .corners import _shortstraw_into, _walk_into, shortstraw_workspace, walk_room
from .turning import TWO_PI, _best_shift_into, _turning_into


@njit(cache=True, nogil=True)
def scan_turning(ranges: np.ndarray, directions: np.ndarray, max_range: float, spacing: float,
                 window: int, t: float, line_threshold: float, close_through_origin: bool,
                 along_path: bool) -> tuple[np.ndarray, np.ndarray]:
    """Breaks and angles of a scan's turning function (empty when its polygon has < 3 edges).

    ``ranges`` (metres) of beams with unit ``directions`` ``(n_beams, 2)``; the other arguments
    are those of :class:`tfloc.paper.matcher.TfConfig`. :func:`_scan_turning_into` with buffers
    of its own: room for the walk as :func:`~tfloc.paper.corners.walk_room` bounds it and,
    should a walk ever be longer, exactly as many points as it has."""
    n_beams = ranges.shape[0]
    pts = _returns_to_points(ranges, directions, max_range)
    ws = turning_workspace(n_beams, 0, walk_room(pts, spacing))
    k = _scan_turning_into(ranges, directions, max_range, spacing, window, t, line_threshold,
                           close_through_origin, along_path, ws)
    if k < 0:
        ws = turning_workspace(n_beams, 0, _walk_into(pts, spacing, along_path, np.empty((0, 2))))
        k = _scan_turning_into(ranges, directions, max_range, spacing, window, t,
                               line_threshold, close_through_origin, along_path, ws)
    if k < 3:
        return np.empty(0), np.empty(0)
    return ws[7][:k + 1].copy(), ws[6][:k].copy()


@njit(cache=True, nogil=True)
def turning_workspace(n_beams: int, n_real: int, walk_rows: int) -> tuple:
    """Buffers for :func:`_scan_turning_into` on scans of ``n_beams`` beams whose ShortStraw
    walk has up to ``walk_rows`` points, and the match against a real turning function of
    ``n_real`` edges: the points, ShortStraw's (:func:`~tfloc.paper.corners.shortstraw_workspace`),
    the polygon, the turning function's, the match's."""
    rows = walk_rows + 3            # the polygon: the origin and at most walk_rows + 2 corners
    return (np.empty((n_beams, 2)), shortstraw_workspace(walk_rows), np.empty((rows, 2)),
            np.empty(rows), np.empty(rows), np.empty(rows), np.empty(rows), np.empty(rows + 1),
            np.empty(rows), np.empty(n_real + 1 + rows), np.empty(n_real + rows),
            np.empty(n_real + rows))


@njit(cache=True, nogil=True)
def _scan_turning_into(ranges: np.ndarray, directions: np.ndarray, max_range: float,
                       spacing: float, window: int, t: float, line_threshold: float,
                       close_through_origin: bool, along_path: bool, ws: tuple) -> int:
    """:func:`scan_turning` in the buffers ``ws`` (:func:`turning_workspace`): returns the number
    of edges ``k`` (the function is ``ws[7][:k + 1]``, ``ws[6][:k]``; none when ``k`` < 3), or −1
    when ShortStraw's walk did not fit (then :func:`scan_turning` gives it): the points (Eq. 4),
    ShortStraw's corners (Algs. 1–3), the closed polygon, its turning function (Alg. 4)."""
    pts_buf, sws, poly, ex, ey, length, angles, breaks = ws[:8]
    n = _returns_to_points_into(ranges, directions, max_range, pts_buf)
    off = 1 if close_through_origin else 0
    if n < 2:
        nc = n
        for i in range(n):
            poly[off + i, 0], poly[off + i, 1] = pts_buf[i, 0], pts_buf[i, 1]
    else:
        nc = _shortstraw_into(pts_buf[:n], spacing, window, t, line_threshold, along_path, sws,
                              poly, off)
        if nc < 0:
            return -1
    if close_through_origin:
        poly[0, 0], poly[0, 1] = 0.0, 0.0
    return _turning_into(poly[:nc + off], ex, ey, length, angles, breaks)


@njit(cache=True, nogil=True)
def wrap_rotation(rot: float) -> float:
    """``(rot + π) % 2π − π``: numba's float ``%`` is CPython's (``fmod``, then the sign fix), so
    this equals :func:`tfloc.core.pose.wrap_angle` bit for bit."""
    return (rot + np.pi) % TWO_PI - np.pi


@njit(cache=True, nogil=True)
def scan_errors(scans: np.ndarray, directions: np.ndarray, max_range: float, spacing: float,
                window: int, t: float, line_threshold: float, close_through_origin: bool,
                along_path: bool, l1: bool, real_breaks: np.ndarray, real_angles: np.ndarray,
                penalty: float) -> tuple[np.ndarray, np.ndarray]:
    """Err (Eq. 13's L2 norm, or the L1 area if ``l1``) and the rotation offset (radians, in
    [-π, π)) of each virtual scan ``(P, n_beams)`` against the real turning function.

    A scan whose polygon has fewer than 3 edges costs ``penalty`` with rotation 0."""
    n = scans.shape[0]
    err = np.full(n, penalty)
    rot = np.zeros(n)
    # room for a walk of 4n + 16 points, without a pass for each scan's path length (this runs
    # for every Function1): by walk_room's bound it holds every path up to (2n + 14)·S, 376 m
    # at tf's S = 1 m for 181 beams (37.6 m at tf-best's 0.1 m); a longer walk goes to
    # scan_turning, which sizes its buffers from the path
    ws = turning_workspace(scans.shape[1], real_angles.shape[0], 4 * scans.shape[1] + 16)
    moved, grid, width, d = ws[8], ws[9], ws[10], ws[11]
    for p in range(n):
        k = _scan_turning_into(scans[p], directions, max_range, spacing, window, t,
                               line_threshold, close_through_origin, along_path, ws)
        if k < 0:                   # a walk too long for the buffers: the allocating path
            vb, va = scan_turning(scans[p], directions, max_range, spacing, window, t,
                                  line_threshold, close_through_origin, along_path)
        elif k < 3:
            continue
        else:
            vb, va = ws[7][:k + 1], ws[6][:k]
        if va.shape[0] < 3:
            continue
        if va.shape[0] > moved.shape[0]:    # (only after the allocating path)
            moved, grid = np.empty(va.shape[0]), np.empty(real_angles.shape[0] + 1 + va.shape[0])
            width, d = np.empty(grid.shape[0]), np.empty(grid.shape[0])
        e, r, _ = _best_shift_into(real_breaks, real_angles, vb, va, l1, moved, grid, width, d)
        err[p] = e if l1 else np.sqrt(max(e, 0.0))
        rot[p] = wrap_rotation(r)
    return err, rot


@njit(cache=True, nogil=True)
def function1_kernel(x: float, y: float, theta_v: float, offsets: np.ndarray, rings: tuple,
                     sure: float, rel_angles: np.ndarray, segs: np.ndarray, index: tuple,
                     directions: np.ndarray,
                     max_range: float, spacing: float, window: int, t: float,
                     line_threshold: float, close_through_origin: bool, along_path: bool,
                     l1: bool, real_breaks: np.ndarray, real_angles: np.ndarray,
                     penalty: float) -> tuple[int, float, float, float]:
    """Alg. 5's Function1 at ``(x, y)`` on a vector map (segments ``segs``, their buckets
    ``index``), in one call: whether
    the position is free (:func:`tfloc.maps.inside.raster_code` on the free space's ``rings`` =
    ``Rings.kernel`` of :class:`~tfloc.maps.inside.Rings`; ``sure`` < 0 skips
    the test, the caller having made it), the virtual scans of the headings
    ``theta_v + offsets`` (:func:`tfloc.maps._raycast.raycast_segments`), their Err and rotation
    offsets (:func:`scan_errors`) and the best of them (the first lowest Err, as ``np.argmin``).

    Returns ``(code, Err, heading, rotation)``: code 1 answered, 0 not free (the rest unset),
    -1 too near the free space's boundary to say (ask shapely, then call again with ``sure`` < 0)."""
    if sure >= 0.0:
        code = raster_code(x, y, rings, sure)
        if code != 1:
            return np.int64(code), penalty, theta_v + offsets[0], 0.0
    n = offsets.shape[0]
    poses = np.empty((n, 3))
    for k in range(n):
        poses[k, 0], poses[k, 1], poses[k, 2] = x, y, theta_v + offsets[k]
    scans = raycast_segments(poses, rel_angles, segs, max_range, index)
    err, rot = scan_errors(scans, directions, max_range, spacing, window, t, line_threshold,
                           close_through_origin, along_path, l1, real_breaks, real_angles, penalty)
    b = 0
    for k in range(n):
        if np.isnan(err[k]):
            b = k
            break
        if err[k] < err[b]:
            b = k
    return np.int64(1), err[b], poses[b, 2], rot[b]
