# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Nav2's laser models (``nav2_amcl/src/sensors/laser/``), compiled with numba: each multiplies
every particle's weight by ``p = 1 + Σ pz³`` over every ``step``-th beam (Nav2's ad-hoc
combination) and returns the sum of the new weights (what ``pf_update_sensor`` normalises by).

* **Likelihood field** (``likelihood_field_model.cpp``): a beam's end point looks up the distance
  ``z`` of its cell to the nearest obstacle (``MAP_GXWX``; off the map ``max_occ_dist``);
  ``pz = z_hit · exp(−z² / 2σ²) + z_rand / range_max``; readings ≥ ``range_max`` or NaN are
  skipped. ``pz³`` depends on the cell alone, so it is tabulated once per map and parameters
  (:func:`likelihood_table`, the same operations on the same numbers: the same bits).
* **Beam model** (``beam_model.cpp``): the expected range is ray-cast from the particle by
  ``map_calc_range`` (Bresenham over cells; unknown and off-map cells stop the beam, as occupied
  ones); ``pz`` = hit + short (``z < 0``) + max (``== range_max``) + random (``< range_max``).

The laser sits at the robot's origin (tfloc's ranges are in the robot frame), so Nav2's
``pf_vector_coord_add(laser_pose, pose)`` only wraps the heading. Geometry arguments are
:attr:`~tfloc.baselines._amcl_map.NavMap.geometry`. Metres, radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def likelihood_table(occ_dist: np.ndarray, z_hit: float, z_rand: float, sigma_hit: float,
                     range_max: float, max_occ_dist: float) -> tuple[np.ndarray, float]:
    """``pz³`` of every cell ``(size_y, size_x)`` and of a point off the map."""
    z_hit_denom = 2 * sigma_hit * sigma_hit
    z_rand_mult = 1.0 / range_max
    H, W = occ_dist.shape
    out = np.empty((H, W))
    for j in range(H):
        for i in range(W):
            z = np.float64(occ_dist[j, i])
            pz = 0.0
            pz += z_hit * math.exp(-(z * z) / z_hit_denom)
            pz += z_rand * z_rand_mult
            out[j, i] = pz * pz * pz
    z = max_occ_dist
    pz = 0.0
    pz += z_hit * math.exp(-(z * z) / z_hit_denom)
    pz += z_rand * z_rand_mult
    return out, pz * pz * pz


@njit(cache=True, nogil=True, inline="always")
def _laser_pose(poses: np.ndarray, j: int) -> tuple[float, float, float]:
    """Particle ``j``'s pose with its heading normalised (the laser sits at the robot's origin)."""
    return poses[j, 0], poses[j, 1], math.atan2(math.sin(poses[j, 2]), math.cos(poses[j, 2]))


@njit(cache=True, nogil=True, error_model="numpy")
def likelihood_field(poses: np.ndarray, weights: np.ndarray, ranges: np.ndarray, bearings: np.ndarray,
                     step: int, range_max: float, table: np.ndarray, off_map: float, origin_x: float,
                     origin_y: float, scale: float, size_x: int, size_y: int) -> float:
    """``LikelihoodFieldModel::sensorFunction``: ``weights`` ``(n,)`` multiplied in place; their sum."""
    total = 0.0
    half_x = size_x // 2
    half_y = size_y // 2
    for j in range(poses.shape[0]):
        x, y, theta = _laser_pose(poses, j)
        p = 1.0
        for i in range(0, ranges.shape[0], step):
            r = ranges[i]
            if r >= range_max:
                continue
            if r != r:
                continue
            a = theta + bearings[i]
            hx = x + r * math.cos(a)
            hy = y + r * math.sin(a)
            mi = int(math.floor((hx - origin_x) / scale + 0.5) + half_x)
            mj = int(math.floor((hy - origin_y) / scale + 0.5) + half_y)
            if mi >= 0 and mi < size_x and mj >= 0 and mj < size_y:
                p += table[mj, mi]
            else:
                p += off_map
        weights[j] *= p
        total += weights[j]
    return total


@njit(cache=True, nogil=True)
def _free(occ: np.ndarray, i: int, j: int, size_x: int, size_y: int) -> bool:
    """Whether a beam passes cell ``(i, j)``: on the map and free (``occ_state == -1``)."""
    return i >= 0 and i < size_x and j >= 0 and j < size_y and occ[j, i] == -1


@njit(cache=True, nogil=True)
def calc_range(occ: np.ndarray, origin_x: float, origin_y: float, scale: float, size_x: int,
               size_y: int, ox: float, oy: float, oa: float, max_range: float) -> float:
    """``map_calc_range``: the range (m) from ``(ox, oy)`` along heading ``oa`` to the first cell
    that is not free (Bresenham; cell distance × scale), or ``max_range``."""
    x0 = int(math.floor((ox - origin_x) / scale + 0.5) + size_x // 2)
    y0 = int(math.floor((oy - origin_y) / scale + 0.5) + size_y // 2)
    x1 = int(math.floor((ox + max_range * math.cos(oa) - origin_x) / scale + 0.5) + size_x // 2)
    y1 = int(math.floor((oy + max_range * math.sin(oa) - origin_y) / scale + 0.5) + size_y // 2)
    if abs(y1 - y0) > abs(x1 - x0):  # steep: step along y (Nav2 swaps the axes, the same cells)
        return _bresenham(occ.T, y0, x0, y1, x1, size_y, size_x, scale, max_range)
    return _bresenham(occ, x0, y0, x1, y1, size_x, size_y, scale, max_range)


@njit(cache=True, nogil=True)
def _bresenham(occ: np.ndarray, x0: int, y0: int, x1: int, y1: int, size_x: int, size_y: int,
               scale: float, max_range: float) -> float:
    """``map_calc_range``'s loop along x (``occ[y, x]``; the transposed grid for a steep beam)."""
    deltax = abs(x1 - x0)
    deltay = abs(y1 - y0)
    error = 0
    deltaerr = deltay
    x = x0
    y = y0
    xstep = 1 if x0 < x1 else -1
    ystep = 1 if y0 < y1 else -1
    if not _free(occ, x, y, size_x, size_y):
        return math.sqrt((x - x0) * (x - x0) + (y - y0) * (y - y0)) * scale
    while x != (x1 + xstep * 1):
        x += xstep
        error += deltaerr
        if 2 * error >= deltax:
            y += ystep
            error -= deltax
        if not _free(occ, x, y, size_x, size_y):
            return math.sqrt((x - x0) * (x - x0) + (y - y0) * (y - y0)) * scale
    return max_range


@njit(cache=True, nogil=True, error_model="numpy")
def beam_model(poses: np.ndarray, weights: np.ndarray, ranges: np.ndarray, bearings: np.ndarray,
               step: int, range_max: float, occ: np.ndarray, origin_x: float, origin_y: float,
               scale: float, size_x: int, size_y: int, z_hit: float, z_short: float, z_max: float,
               z_rand: float, sigma_hit: float, lambda_short: float) -> float:
    """``BeamModel::sensorFunction``: ``weights`` ``(n,)`` multiplied in place; their sum."""
    total = 0.0
    for j in range(poses.shape[0]):
        x, y, theta = _laser_pose(poses, j)
        p = 1.0
        for i in range(0, ranges.shape[0], step):
            obs_range = ranges[i]
            map_range = calc_range(occ, origin_x, origin_y, scale, size_x, size_y, x, y,
                                   theta + bearings[i], range_max)
            pz = 0.0
            z = obs_range - map_range
            pz += z_hit * math.exp(-(z * z) / (2 * sigma_hit * sigma_hit))
            if z < 0:
                pz += z_short * lambda_short * math.exp(-lambda_short * obs_range)
            if obs_range == range_max:
                pz += z_max * 1.0
            if obs_range < range_max:
                pz += z_rand * 1.0 / range_max
            p += pz * pz * pz
        weights[j] *= p
        total += weights[j]
    return total


def beam_step(range_count: int, max_beams: int) -> int:
    """Every how many beams a model looks at: ``(range_count − 1) / (max_beams − 1)`` (integer
    division), at least 1 (the likelihood field's guard; the beam model lacks it and loops forever
    when ``max_beams`` exceeds the scan's beams)."""
    return max(1, (range_count - 1) // (max_beams - 1))
