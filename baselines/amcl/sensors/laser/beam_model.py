# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/sensors/laser/beam_model.cpp``: Nav2's beam laser model
(``BeamModel::sensorFunction``), compiled with numba; the contract the models share is
:mod:`.laser`'s.

The expected range is ray-cast from the particle by ``map_calc_range``
(:mod:`tfloc.baselines.amcl.map.map_range`: Bresenham over cells; unknown and off-map cells stop
the beam, as occupied ones); ``pz`` = hit + short (``z < 0``) + max (``== range_max``) + random
(``< range_max``). Metres, radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ...map.map_range import calc_range
from .laser import laser_pose


@njit(cache=True, nogil=True, error_model="numpy")
def beam_model(poses: np.ndarray, weights: np.ndarray, ranges: np.ndarray, bearings: np.ndarray,
               step: int, range_max: float, occ: np.ndarray, origin_x: float, origin_y: float,
               scale: float, size_x: int, size_y: int, z_hit: float, z_short: float, z_max: float,
               z_rand: float, sigma_hit: float, lambda_short: float) -> float:
    """``BeamModel::sensorFunction``: ``weights`` ``(n,)`` multiplied in place; their sum."""
    total = 0.0
    for j in range(poses.shape[0]):
        x, y, theta = laser_pose(poses, j)
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
