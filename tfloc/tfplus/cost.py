"""The objective ``tf-plus`` ranks its refined candidates by (and reports as its ``score``).

Per beam of the real scan, at a candidate pose with its virtual scan (metres², truncated at
``c`` = ``inlier_distance``):

* a return: its squared point-to-line distance to the virtual scan (:mod:`tfloc.tfplus.refine`),
  truncated at ``c``;
* with ``beam_check``, a beam the map says cannot be (**see-through**): the real return lies
  more than ``c`` *beyond* the virtual one, or the real beam has no return where the virtual one
  hits a wall. It costs ``c²``. (A real return *short* of the virtual one is an occlusion by
  something the map lacks and is left to the point-to-line term.)

The cost is the mean over all beams. Without the beam check two poses that see the same walls
(a bare corner, a corridor) tie even when one of them would see through a wall; the check is
the beam model's free-space evidence, which point-to-line matching ignores.
"""

from __future__ import annotations

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map

from .refine import residuals_to


def scan_cost(map_: Map, laser: LaserSpec, ranges: np.ndarray, poses: np.ndarray, window: int,
              inlier_distance: float, beam_check: bool = True) -> np.ndarray:
    """Cost ``(K,)`` (metres²) of the real scan ``ranges`` at each of ``(K, 3)`` poses."""
    c = inlier_distance
    virtual = np.atleast_2d(map_.raycast(poses, laser))
    real_ok = laser.valid(ranges)
    pen = np.zeros(virtual.shape)
    if real_ok.any():
        r = residuals_to(virtual, laser, laser.to_points(ranges), window)
        pen[:, real_ok] = np.where(np.isnan(r), c, np.minimum(r, c)) ** 2
    if beam_check:
        virt_ok = laser.valid(virtual)
        with np.errstate(invalid="ignore"):
            through = virt_ok & ((real_ok & (ranges > virtual + c)) | ~real_ok)
        pen[through] = c * c
    return pen.mean(axis=1)
