# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Nav2's odometry motion models, ``nav2_amcl/src/motion_model/``: ``differential_motion_model.cpp``,
``omni_motion_model.cpp``."""
