# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/sensors/laser/laser.cpp`` (and ``include/nav2_amcl/sensors/laser/laser.hpp``):
what Nav2's laser models share, the ``Laser`` base class's beam count and laser pose.

Each model (:mod:`.likelihood_field_model`, :mod:`.beam_model`) multiplies every particle's weight
by ``p = 1 + Σ pz³`` over every ``step``-th beam (Nav2's ad-hoc combination; :func:`beam_step`)
and returns the sum of the new weights (what ``pf_update_sensor`` normalises by). The laser sits
at the robot's origin (tfloc's ranges are in the robot frame), so Nav2's
``pf_vector_coord_add(laser_pose, pose)`` only wraps the heading (:func:`laser_pose`). Geometry
arguments are :attr:`~tfloc.baselines.amcl.map.map.NavMap.geometry`. Metres, radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def laser_pose(poses: np.ndarray, j: int) -> tuple[float, float, float]:
    """Particle ``j``'s pose with its heading normalised (the laser sits at the robot's origin)."""
    return poses[j, 0], poses[j, 1], math.atan2(math.sin(poses[j, 2]), math.cos(poses[j, 2]))


def beam_step(range_count: int, max_beams: int) -> int:
    """Every how many beams a model looks at: ``(range_count − 1) / (max_beams − 1)`` (integer
    division), at least 1 (the likelihood field's guard; the beam model lacks it and loops forever
    when ``max_beams`` exceeds the scan's beams)."""
    return max(1, (range_count - 1) // (max_beams - 1))
