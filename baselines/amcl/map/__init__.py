# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Nav2's map, ``nav2_amcl/src/map/``: ``map.c``, ``map_cspace.cpp``, ``map_range.c``."""
