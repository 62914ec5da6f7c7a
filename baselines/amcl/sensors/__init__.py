# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Nav2's sensor models, ``nav2_amcl/src/sensors/`` (the laser's only: :mod:`.laser`)."""
