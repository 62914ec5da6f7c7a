# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Nav2's laser models, ``nav2_amcl/src/sensors/laser/``: ``laser.cpp``, ``likelihood_field_model.cpp``,
``beam_model.cpp``."""
