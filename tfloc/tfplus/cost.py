"""The objective ``tf-plus`` ranks its refined candidates by (and reports as its ``score``).

Per beam of the real scan, at a candidate pose (metres², truncated at ``c`` = ``inlier_distance``,
10 cm):

* a return: its squared point-to-line distance to the map, truncated at ``c``: to the nearest
  map point of its cell (:func:`tfloc.tfplus.refine.field_pairs`'s ranking residual, which also counts
  a point beyond the end of a wall as off it), or with ``select="virtual"`` to the virtual scan
  (the rule before the real logs; on a grid with thick walls the virtual scan is short);
* with ``beam_check``, a beam the map says cannot be (**see-through**): the real return lies
  more than ``c`` *beyond* the wall the beam meets first, or the real beam has no return where
  the map has a wall within range. It costs ``c²``. (A real return *short* of the wall is an
  occlusion by something the map lacks and is left to the point-to-line term.) On a grid map
  "beyond the wall" means beyond its far side, where the run of occupied cells ends
  (:func:`see_through`); on a vector map, beyond the ray-cast range.

The cost is the mean over all beams. Without the beam check two poses that see the same walls
(a bare corner, a corridor) tie even when one of them would see through a wall; the check is
the beam model's free-space evidence, which point-to-line matching ignores.

Why the far side on grids: a return lies inside the thick wall it hit, and the rule "beyond the
first occupied cell" counted about a quarter of all beams at the true poses as seen through a
wall, penalising the truth as much as a wrong pose (measured: ``docs/tf-plus.md``, "Real logs").
"""

from __future__ import annotations

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap

from .cost_kernel import grid_cost_kernel, see_through_kernel, vector_cost_kernel
from .refine import field_pairs, residuals_to
from .view import MapView


def scan_cost(map_: Map, laser: LaserSpec, ranges: np.ndarray, poses: np.ndarray, window: int,
              inlier_distance: float, beam_check: bool = True,
              field: MapView | None = None) -> np.ndarray:
    """Cost ``(K,)`` (metres²) of the real scan ``ranges`` at each of ``(K, 3)`` poses. The
    point-to-line term is to the map's nearest points (``field``, see :mod:`tfloc.tfplus.refine`), or,
    without a field, to the virtual scans (ray-cast). On vector and grid maps with a field it is
    one compiled call (:func:`_compiled_cost`); :func:`scan_cost_steps` is the same cost in numpy
    steps (the reference of the tests) and serves every other case."""
    poses = np.reshape(poses, (-1, 3))
    if field is not None and isinstance(map_, VectorMap | GridMap):
        return _compiled_cost(map_, laser, ranges, poses, inlier_distance, beam_check, field)
    return scan_cost_steps(map_, laser, ranges, poses, window, inlier_distance, beam_check, field)


def _compiled_cost(map_: VectorMap | GridMap, laser: LaserSpec, ranges: np.ndarray,
                   poses: np.ndarray, c: float, beam_check: bool, field: MapView) -> np.ndarray:
    """:func:`scan_cost_steps` in one compiled call (:mod:`tfloc.tfplus.cost_kernel`): the same
    values."""
    poses = np.ascontiguousarray(poses, dtype=float)
    ranges = np.ascontiguousarray(ranges, dtype=float)
    args = (field.nearest, float(field.origin[0]), float(field.origin[1]), field.resolution,
            field.points, field.normals, ranges, laser.directions, laser.angles,
            float(laser.max_range), poses)
    if isinstance(map_, GridMap):
        return grid_cost_kernel(*args, map_.occupied, float(map_.origin[0]),
                                float(map_.origin[1]), float(map_.resolution), c, beam_check)
    return vector_cost_kernel(*args, map_.segments, map_.segment_index(float(laser.max_range)), c,
                              beam_check)


def scan_cost_steps(map_: Map, laser: LaserSpec, ranges: np.ndarray, poses: np.ndarray,
                    window: int, inlier_distance: float, beam_check: bool = True,
                    field: MapView | None = None) -> np.ndarray:
    """:func:`scan_cost` in numpy steps, for any map."""
    c = inlier_distance
    poses = np.reshape(poses, (-1, 3))
    real_ok = laser.valid(ranges)
    pen = np.zeros((len(poses), laser.n_beams))
    virtual = None
    if real_ok.any():
        if field is not None:
            r = field_pairs(field, laser.to_points(ranges), poses, c)[3]
        else:
            virtual = np.atleast_2d(map_.raycast(poses, laser))
            r = residuals_to(virtual, laser, laser.to_points(ranges), window)
        pen[:, real_ok] = np.where(np.isnan(r), c, np.minimum(r, c)) ** 2
    if beam_check:
        pen[see_through(map_, laser, ranges, poses, c, virtual if field is None else None)] = c * c
    return pen.mean(axis=1)


def see_through(map_: Map, laser: LaserSpec, ranges: np.ndarray, poses: np.ndarray, margin: float,
                virtual: np.ndarray | None = None) -> np.ndarray:
    """Which beams ``(K, n_beams)`` the map says cannot be at each of ``(K, 3)`` poses (see the
    module docstring). On a grid map "beyond the wall" means beyond its far side
    (:func:`~tfloc.tfplus.cost_kernel.see_through_kernel`): the real returns of a wall drawn
    several cells thick lie anywhere inside it. On other maps, beyond the ray-cast range
    (``virtual``, computed if not given)."""
    poses = np.reshape(poses, (-1, 3))
    if isinstance(map_, GridMap):
        return see_through_kernel(map_.occupied, map_.origin[0], map_.origin[1], map_.resolution,
                                  np.ascontiguousarray(poses, dtype=float),
                                  np.asarray(laser.angles, dtype=float),
                                  np.asarray(ranges, dtype=float), float(laser.max_range), margin)
    if virtual is None:
        virtual = np.atleast_2d(map_.raycast(poses, laser))
    real_ok = laser.valid(ranges)
    with np.errstate(invalid="ignore"):
        return laser.valid(virtual) & ((real_ok & (ranges > virtual + margin)) | ~real_ok)
