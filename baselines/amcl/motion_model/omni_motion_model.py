# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/motion_model/omni_motion_model.cpp``: Nav2's odometry motion model
of an omnidirectional base, compiled with numba.

Arguments and draws as in :mod:`.differential_motion_model` (odometry pose and its change since
the last update, odometry frame; three Gaussian draws per particle; headings not wrapped).

``OmniMotionModel::odometryUpdate``: translation, rotation and strafe, each with its own noise
(``alpha5`` for strafe).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..angleutils import angle_diff
from ..pf.pf_pdf import ran_gaussian


@njit(cache=True, nogil=True)
def omni(state: np.ndarray, poses: np.ndarray, pose: np.ndarray, delta: np.ndarray, alpha1: float,
         alpha2: float, alpha3: float, alpha4: float, alpha5: float) -> None:
    """``OmniMotionModel::odometryUpdate``: ``poses`` ``(n, 3)`` moved in place."""
    old_theta = pose[2] - delta[2]
    trans = math.sqrt(delta[0] * delta[0] + delta[1] * delta[1])
    rot = delta[2]
    sd_trans = math.sqrt(alpha3 * (trans * trans) + alpha4 * (rot * rot))
    sd_rot = math.sqrt(alpha1 * (rot * rot) + alpha2 * (trans * trans))
    sd_strafe = math.sqrt(alpha4 * (rot * rot) + alpha5 * (trans * trans))
    for i in range(poses.shape[0]):
        bearing = angle_diff(math.atan2(delta[1], delta[0]), old_theta) + poses[i, 2]
        cs = math.cos(bearing)
        sn = math.sin(bearing)
        trans_hat = trans + ran_gaussian(state, sd_trans)
        rot_hat = rot + ran_gaussian(state, sd_rot)
        strafe_hat = 0 + ran_gaussian(state, sd_strafe)
        poses[i, 0] += (trans_hat * cs + strafe_hat * sn)
        poses[i, 1] += (trans_hat * sn - strafe_hat * cs)
        poses[i, 2] += rot_hat
