# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""``amcl``: Nav2's AMCL (``nav2_amcl``, ros-navigation/navigation2) ported to numba, one module
per Nav2 source file, in Nav2's folders (the table: ``docs/baselines/amcl.md``):

* ``node`` ↔ ``src/amcl_node.cpp``: :class:`AmclTracker` (the registered tracker ``amcl``) and its
  :class:`Config`; ``angleutils`` ↔ ``include/nav2_amcl/angleutils.hpp``;
* ``pf/`` ↔ ``src/pf/``: ``pf`` (``pf.c``), ``pf_kdtree``, ``pf_pdf``, ``eig3``;
* ``map/`` ↔ ``src/map/``: ``map`` (``map.c``, ``map.hpp``), ``map_cspace``, ``map_range``;
* ``sensors/laser/`` ↔ ``src/sensors/laser/``: ``laser``, ``likelihood_field_model``, ``beam_model``;
* ``motion_model/`` ↔ ``src/motion_model/``: ``differential_motion_model``, ``omni_motion_model``.

A translation of nav2_amcl's LGPL-2.1-or-later code. What it shares with ``amcl-wheel`` (tfloc's
own code) is :mod:`tfloc.baselines._amcl_common`.
"""

from .node import AmclTracker, Config

__all__ = ["AmclTracker", "Config"]
