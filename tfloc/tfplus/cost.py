"""The objective ``tf-plus`` ranks its refined candidates by (and reports as its ``score``).

Per beam of the real scan, at a candidate pose (metres², truncated at ``c`` = ``inlier_distance``,
10 cm):

* a return: its squared point-to-line distance to the map, truncated at ``c``: to the nearest
  map point of its cell (:func:`tfloc.tfplus.refine.field_pairs`'s ranking residual, which also counts
  a point beyond the end of a wall as off it), or with ``select="virtual"`` to the virtual scan
  (the rule before the real logs; on a grid with thick walls the virtual scan is short);
* with ``beam_check``, a beam the map says cannot be (**see-through**): the real return lies
  more than ``c`` *beyond* the wall the beam meets first, or the real beam has no return where
  the map has a wall within range. It costs ``c²``. On a grid map "beyond the wall" means
  beyond its far side, where the run of occupied cells ends (:func:`see_through`); on a vector
  map, beyond the ray-cast range. With ``see_through_share`` < 1 they count in full only up to
  that share of the beams (:func:`bound_see_through`): where the map has objects the world has
  lost (furniture gone), many beams pass them at the true pose too;
* with ``short_residual`` = ``s``, a **short** return (:func:`short_beams`), one the map says is
  clear of walls up to ``short_margin`` (30 cm) beyond it, costs at most ``s²`` when its whole
  group of returns is short (:func:`unmapped`): something the map lacks (a person, a cart)
  stopped it, which says little against the pose. The margin is well above ``c``, so that a
  pose a few cm off does not make its own errors short; with ``object_extent`` a group is an
  object-sized run of consecutive returns (:func:`object_groups`: a wall's worth of short
  returns says the pose is wrong), without it each return on its own. Without
  ``short_residual`` such a return costs its residual like any other, up to ``c²``.

The cost is the mean over all beams. The beam check is the beam model's free-space evidence,
which point-to-line matching ignores (two poses that see the same walls otherwise tie). The far
side on grids: a return lies inside the thick wall it hit (``docs/tf-plus.md``, "Real logs").
"""

from __future__ import annotations

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap

from .cost_kernel import (
    beam_flags_kernel,
    grid_cost_kernel,
    object_groups_kernel,
    see_through_kernel,
    unmapped_kernel,
    vector_cost_kernel,
)
from .refine import field_pairs, residuals_to
from .view import MapView


def scan_cost(map_: Map, laser: LaserSpec, ranges: np.ndarray, poses: np.ndarray, window: int,
              inlier_distance: float, beam_check: bool = True, field: MapView | None = None,
              short_residual: float | None = None, see_through_share: float = 1.0,
              short_margin: float = 0.3, object_extent: float | None = None) -> np.ndarray:
    """Cost ``(K,)`` (metres²) of the real scan ``ranges`` at each of ``(K, 3)`` poses. The
    point-to-line term is to the map's nearest points (``field``, see :mod:`tfloc.tfplus.refine`), or,
    without a field, to the virtual scans (ray-cast). On vector and grid maps with a field it is
    one compiled call (:func:`_compiled_cost`); :func:`scan_cost_steps` is the same cost in numpy
    steps (the reference of the tests) and serves every other case."""
    poses = np.reshape(poses, (-1, 3))
    if field is not None and isinstance(map_, VectorMap | GridMap):
        return _compiled_cost(map_, laser, ranges, poses, inlier_distance, beam_check, field,
                              short_residual, see_through_share, short_margin, object_extent)
    return scan_cost_steps(map_, laser, ranges, poses, window, inlier_distance, beam_check, field,
                           short_residual, see_through_share, short_margin, object_extent)


def _compiled_cost(map_: VectorMap | GridMap, laser: LaserSpec, ranges: np.ndarray,
                   poses: np.ndarray, c: float, beam_check: bool, field: MapView,
                   short_residual: float | None = None, see_through_share: float = 1.0,
                   short_margin: float = 0.3, object_extent: float | None = None) -> np.ndarray:
    """:func:`scan_cost_steps` in one compiled call (:mod:`tfloc.tfplus.cost_kernel`): the same
    values."""
    short = -1.0 if short_residual is None else float(short_residual)
    groups = object_groups(laser, ranges, object_extent)
    poses = np.ascontiguousarray(poses, dtype=float)
    ranges = np.ascontiguousarray(ranges, dtype=float)
    args = (field.nearest, float(field.origin[0]), float(field.origin[1]), field.resolution,
            field.points, field.normals, ranges, laser.directions, laser.angles,
            float(laser.max_range), poses)
    if isinstance(map_, GridMap):
        return grid_cost_kernel(*args, map_.occupied, float(map_.origin[0]),
                                float(map_.origin[1]), float(map_.resolution), c, beam_check,
                                map_.free, short, float(see_through_share), float(short_margin),
                                groups)
    return vector_cost_kernel(*args, map_.segments, map_.segment_index(float(laser.max_range)), c,
                              beam_check, short, float(see_through_share), float(short_margin),
                              groups)


def scan_cost_steps(map_: Map, laser: LaserSpec, ranges: np.ndarray, poses: np.ndarray,
                    window: int, inlier_distance: float, beam_check: bool = True,
                    field: MapView | None = None, short_residual: float | None = None,
                    see_through_share: float = 1.0, short_margin: float = 0.3,
                    object_extent: float | None = None) -> np.ndarray:
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
    if short_residual is not None:
        near = unmapped(short_beams(map_, laser, ranges, poses, short_margin, virtual),
                        object_groups(laser, ranges, object_extent))
        pen[near] = np.minimum(pen[near], short_residual * short_residual)
    if beam_check:
        see = see_through(map_, laser, ranges, poses, c, virtual if field is None else None)
        bound_see_through(pen, see, c, see_through_share)
    return pen.mean(axis=1)


def bound_see_through(pen: np.ndarray, see: np.ndarray, c: float, share: float) -> None:
    """Set ``pen`` ``(K, n)`` (metres²) to ``c²`` at the see-through beams ``see`` of each pose
    while they are at most ``share`` of the beams; beyond that move each one's penalty towards
    ``c²`` by ``share · n / count`` (in place; see the module docstring)."""
    cap = share * pen.shape[1]
    for k in range(len(pen)):
        m = int(see[k].sum())
        if m == 0:
            continue
        if m <= cap:
            pen[k, see[k]] = c * c
        else:
            pen[k, see[k]] = pen[k, see[k]] + (cap / m) * (c * c - pen[k, see[k]])


def object_groups(laser: LaserSpec, ranges: np.ndarray, max_extent: float | None) -> np.ndarray:
    """The scan's object-sized groups of consecutive returns ``(n,)``, a label per beam (-1:
    none; :func:`~tfloc.tfplus.cost_kernel.object_groups_kernel`: at most ``max_extent`` metres
    from first to last return); every return a group of its own if ``max_extent`` is ``None``."""
    return object_groups_kernel(np.ascontiguousarray(ranges, dtype=float), laser.directions,
                                float(laser.max_range), float(laser.resolution),
                                -1.0 if max_extent is None else float(max_extent))


def unmapped(short: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """The returns ``(K, n)`` whose whole group (``groups``, :func:`object_groups`) is ``short``
    ``(K, n)`` at a pose: an object the map lacks, not a pose error at a wall's edge."""
    return unmapped_kernel(np.ascontiguousarray(short, dtype=bool), groups)


def short_beams(map_: Map, laser: LaserSpec, ranges: np.ndarray, poses: np.ndarray,
                margin: float, virtual: np.ndarray | None = None) -> np.ndarray:
    """Which beams ``(K, n_beams)`` are **short** at each of ``(K, 3)`` poses: a return the map
    says is clear of walls up to ``margin`` beyond it. On a grid map the return's cell must be
    known free and the ray meets no occupied cell before ``r + margin``
    (:func:`~tfloc.tfplus.cost_kernel.beam_flags_kernel`); on other maps the ray-cast range
    (``virtual``, computed if not given) has no wall or one beyond ``r + margin``."""
    poses = np.reshape(poses, (-1, 3))
    if isinstance(map_, GridMap):
        return beam_flags_kernel(map_.occupied, map_.free, map_.origin[0], map_.origin[1],
                                 map_.resolution, np.ascontiguousarray(poses, dtype=float),
                                 np.asarray(laser.angles, dtype=float),
                                 np.asarray(ranges, dtype=float), float(laser.max_range),
                                 margin, margin, False, np.ones(len(ranges), dtype=bool))[1]
    if virtual is None:
        virtual = np.atleast_2d(map_.raycast(poses, laser))
    real_ok = laser.valid(ranges)
    with np.errstate(invalid="ignore"):
        return real_ok & (~laser.valid(virtual) | (ranges < virtual - margin))


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
