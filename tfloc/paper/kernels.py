"""The ``tf`` cost evaluation after the virtual scan, fused into one compiled call per batch.

One call takes the virtual scans of a batch of poses (the seven orientations of Alg. 5's
Function1) and returns Err and the rotation offset for each: ranges → points (Eq. 4) →
ShortStraw corners (Algs. 1–3) → closed scan polygon → turning function (Alg. 4) → matching
against the real scan's turning function (Sec. 4.3 / Eq. 13). It runs exactly the compiled
kernels that the step-by-step path (:func:`tfloc.paper.shape.scan_turning_function`, :func:`tfloc.paper.turning.match`)
calls one by one from Python, in the same order with the same arithmetic, so both give identical
results (tests/test_perf_tf_equivalence.py); only the Python overhead per pose is gone.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from tfloc.core.laser import _returns_to_points
from tfloc.maps._raycast import raycast_segments
from tfloc.maps.inside import raster_code

from .corners import _shortstraw
from .turning import TWO_PI, _match, _match_l1, _turning


@njit(cache=True, nogil=True)
def scan_turning(ranges: np.ndarray, directions: np.ndarray, max_range: float, spacing: float,
                 window: int, t: float, line_threshold: float, close_through_origin: bool,
                 along_path: bool) -> tuple[np.ndarray, np.ndarray]:
    """Breaks and angles of a scan's turning function (empty when its polygon has < 3 edges).

    ``ranges`` (metres) of beams with unit ``directions`` ``(n_beams, 2)``; the other arguments
    are those of :class:`tfloc.paper.matcher.TfConfig`."""
    pts = _returns_to_points(ranges, directions, max_range)
    if pts.shape[0] < 2:
        corners = pts.copy()
    else:
        corners = _shortstraw(pts, spacing, window, t, line_threshold, along_path)
    if close_through_origin:
        poly = np.zeros((corners.shape[0] + 1, 2))
        poly[1:] = corners
        return _turning(poly)
    return _turning(corners)


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
    for p in range(n):
        vb, va = scan_turning(scans[p], directions, max_range, spacing, window, t, line_threshold,
                              close_through_origin, along_path)
        if va.shape[0] < 3:
            continue
        if l1:
            e, r, _ = _match_l1(real_breaks, real_angles, vb, va)
            err[p] = e
        else:
            e2, r, _ = _match(real_breaks, real_angles, vb, va)
            err[p] = np.sqrt(max(e2, 0.0))
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
