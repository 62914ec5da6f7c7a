# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/include/nav2_amcl/angleutils.hpp``: ``angleutils::normalize`` and
``angle_diff`` (radians), which the update gate (:mod:`.node`) and the motion models use.
Compiled with numba.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, nogil=True)
def normalize(z: float) -> float:
    """``angleutils::normalize``: ``atan2(sin z, cos z)``."""
    return math.atan2(math.sin(z), math.cos(z))


@njit(cache=True, nogil=True)
def angle_diff(a: float, b: float) -> float:
    """``angleutils::angle_diff``: ``a − b`` wrapped into [−π, π] (radians)."""
    a = normalize(a)
    b = normalize(b)
    d1 = a - b
    d2 = 2 * math.pi - abs(d1)
    if d1 > 0:
        d2 *= -1.0
    if abs(d1) < abs(d2):
        return d1
    return d2
