# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/motion_model/differential_motion_model.cpp``: Nav2's default
odometry motion model, compiled with numba.

``pose`` is the odometry pose at this update and ``delta`` its change since the last update, both
in the odometry frame (``AmclNode::shouldUpdateFilter``: ``Δx``, ``Δy`` and ``angle_diff`` of the
headings). Every particle moves by its own noisy copy of the motion, three Gaussian draws each
from the filter's stream (:mod:`tfloc.baselines.amcl.pf.pf_pdf`); headings are not wrapped, as Nav2.

``DifferentialMotionModel::odometryUpdate`` is ``sample_motion_model_odometry`` (Probabilistic
Robotics p. 136) with Nav2's symmetric noise for backward motion (rotations measured from 0 or π,
whichever is nearer) and no initial rotation below 1 cm of travel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..angleutils import angle_diff
from ..pf.pf_pdf import ran_gaussian


@njit(cache=True, nogil=True)
def differential(state: np.ndarray, poses: np.ndarray, pose: np.ndarray, delta: np.ndarray,
                 alpha1: float, alpha2: float, alpha3: float, alpha4: float) -> None:
    """``DifferentialMotionModel::odometryUpdate``: ``poses`` ``(n, 3)`` moved in place."""
    old_theta = pose[2] - delta[2]
    if math.sqrt(delta[1] * delta[1] + delta[0] * delta[0]) < 0.01:
        rot1 = 0.0
    else:
        rot1 = angle_diff(math.atan2(delta[1], delta[0]), old_theta)
    trans = math.sqrt(delta[0] * delta[0] + delta[1] * delta[1])
    rot2 = angle_diff(delta[2], rot1)
    rot1_noise = min(abs(angle_diff(rot1, 0.0)), abs(angle_diff(rot1, math.pi)))
    rot2_noise = min(abs(angle_diff(rot2, 0.0)), abs(angle_diff(rot2, math.pi)))
    sd_rot1 = math.sqrt(alpha1 * rot1_noise * rot1_noise + alpha2 * trans * trans)
    sd_trans = math.sqrt(alpha3 * trans * trans + alpha4 * rot1_noise * rot1_noise
                         + alpha4 * rot2_noise * rot2_noise)
    sd_rot2 = math.sqrt(alpha1 * rot2_noise * rot2_noise + alpha2 * trans * trans)
    for i in range(poses.shape[0]):
        rot1_hat = angle_diff(rot1, ran_gaussian(state, sd_rot1))
        trans_hat = trans - ran_gaussian(state, sd_trans)
        rot2_hat = angle_diff(rot2, ran_gaussian(state, sd_rot2))
        poses[i, 0] += trans_hat * math.cos(poses[i, 2] + rot1_hat)
        poses[i, 1] += trans_hat * math.sin(poses[i, 2] + rot1_hat)
        poses[i, 2] += rot1_hat + rot2_hat
