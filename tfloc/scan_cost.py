"""The objective ``tf-plus`` ranks its refined candidates by (and reports as its ``score``).

Per beam of the real scan, at a candidate pose with its virtual scan (metres², truncated at
``c`` = ``inlier_distance``):

* a return: its squared point-to-line distance to the virtual scan (:mod:`tfloc.refine`),
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

from .distance_field import DistanceField
from .laser import LaserSpec
from .maps.base import Map
from .refine import field_pairs, residuals_to


def scan_cost(map_: Map, laser: LaserSpec, ranges: np.ndarray, poses: np.ndarray, window: int,
              inlier_distance: float, beam_check: bool = True,
              field: DistanceField | None = None) -> np.ndarray:
    """Cost ``(K,)`` (metres²) of the real scan ``ranges`` at each of ``(K, 3)`` poses. The
    point-to-line term is to the map's nearest points (``field``, see :mod:`tfloc.refine`), or,
    without a field, to the virtual scans."""
    c = inlier_distance
    poses = np.reshape(poses, (-1, 3))
    virtual = np.atleast_2d(map_.raycast(poses, laser)) if beam_check or field is None else None
    real_ok = laser.valid(ranges)
    pen = np.zeros((len(poses), laser.n_beams))
    if real_ok.any():
        if field is not None:
            r = field_pairs(field, laser.to_points(ranges), poses, c)[3]
        else:
            r = residuals_to(virtual, laser, laser.to_points(ranges), window)
        pen[:, real_ok] = np.where(np.isnan(r), c, np.minimum(r, c)) ** 2
    if beam_check:
        virt_ok = laser.valid(virtual)
        far = virtual
        if field is not None and hasattr(map_, "raycast_far_side"):
            far = np.atleast_2d(map_.raycast_far_side(poses, laser))
        with np.errstate(invalid="ignore"):
            through = virt_ok & ((real_ok & (ranges > far + c)) | ~real_ok)
        pen[through] = c * c
    return pen.mean(axis=1)
