# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/sensors/laser/likelihood_field_model.cpp``: Nav2's default laser
model (``LikelihoodFieldModel::sensorFunction``), compiled with numba; the contract the models
share is :mod:`.laser`'s.

A beam's end point looks up the distance ``z`` of its cell to the nearest obstacle (``MAP_GXWX``;
off the map ``max_occ_dist``; the distances are :mod:`tfloc.baselines.amcl.map.map_cspace`'s);
``pz = z_hit · exp(−z² / 2σ²) + z_rand / range_max``; readings ≥ ``range_max`` or NaN are
skipped. ``pz³`` depends on the cell alone, so it is tabulated once per map and parameters
(:func:`likelihood_table`, the same operations on the same numbers: the same bits). Metres, radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .laser import laser_pose


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


@njit(cache=True, nogil=True, error_model="numpy")
def likelihood_field(poses: np.ndarray, weights: np.ndarray, ranges: np.ndarray, bearings: np.ndarray,
                     step: int, range_max: float, table: np.ndarray, off_map: float, origin_x: float,
                     origin_y: float, scale: float, size_x: int, size_y: int) -> float:
    """``LikelihoodFieldModel::sensorFunction``: ``weights`` ``(n,)`` multiplied in place; their sum."""
    total = 0.0
    half_x = size_x // 2
    half_y = size_y // 2
    for j in range(poses.shape[0]):
        x, y, theta = laser_pose(poses, j)
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
