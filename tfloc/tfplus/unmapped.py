"""Returns from objects the map lacks, left out of the refinement against the map itself.

The refinement against the map (:func:`tfloc.tfplus.refine.refine_to_field`) pairs each scan point
with its cell's nearest map point. A return from a person or a cart standing in free space then
pairs with whatever wall lies within the gate (0.5 m at first) and pulls the pose towards it; a
refinement against virtual scans does not, because it pairs along the beam, where the map's wall
lies behind the object. Here the returns of a group the map says is clear of walls up to
``gate`` beyond it as a whole (:func:`tfloc.tfplus.cost.unmapped`), and that lie more than
``gate`` from every map point (:func:`off_map_kernel`), are left out of a candidate's
refinement. (Without the second test a pose 10 cm and 1° off makes the returns of small mapped
things, a chair's legs, a door frame, look short, and the refinement loses them: measured on
the real logs.) Each candidate is refined on its own returns, decided at its coarse pose and
again after the pruning, which keeps the ``keep`` candidates of lowest *selection* cost (the
refinement's own truncated residual counts every return of a person as an outlier, and ties
where the scan sees the same walls from two places, which the see-through term breaks). The same
as the compiled pipeline's (:mod:`tfloc.tfplus.pipeline`), pose for pose.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numba import njit

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map

from .cost import short_beams, unmapped
from .field_kernel import _to_nearest, refine_to_field_kernel
from .refine import RefineConfig, field_refinement
from .view import MapView
from .virtual_kernel import prune_index_kernel


@njit(cache=True, nogil=True)
def off_map_kernel(view: tuple, points: np.ndarray, pose: np.ndarray, margin: float) -> np.ndarray:
    """Which scan ``points`` ``(M, 2)`` (sensor frame) lie more than ``margin`` metres from their
    cell's nearest map point at ``pose`` ``(3,)`` (``view`` = (nearest, origin x, origin y,
    resolution, map points, map normals), the compiled refinement's)."""
    nearest, fx, fy, fres, map_points = view[0], view[1], view[2], view[3], view[4]
    field = (nearest, fx, fy, 1.0 / fres, map_points)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    out = np.zeros(points.shape[0], dtype=np.bool_)
    for i in range(points.shape[0]):
        _, _, j, dx, dy = _to_nearest(field, pose[0], pose[1], c, s, points[i, 0], points[i, 1])
        out[i] = j < 0 or math.sqrt(dx * dx + dy * dy) > margin
    return out


@njit(cache=True, nogil=True)
def refine_each_kernel(view: tuple, points: np.ndarray, ranges: np.ndarray, poses: np.ndarray,
                       inlier: float, refine: tuple, short: np.ndarray, max_range: float,
                       min_returns: int, gate: float) -> np.ndarray:
    """Each of ``(K, 3)`` poses refined against the map (``refine``: the compiled refinement's
    tuple) on the returns (``points``, in beam order of ``ranges``) but those its row of
    ``short`` ``(K, n)`` flags and that lie more than ``gate`` from the map (all of them if
    fewer than ``min_returns`` would remain)."""
    out = np.empty((poses.shape[0], 3))
    for k in range(poses.shape[0]):
        off = off_map_kernel(view, points, poses[k], gate)
        keep = np.zeros(points.shape[0], dtype=np.bool_)
        i = 0
        for b in range(ranges.shape[0]):
            r = ranges[b]
            if np.isfinite(r) and r > 0.0 and r < max_range:
                keep[i] = not (short[k, b] and off[i])
                i += 1
        mine = points[keep] if keep.sum() >= min_returns else points
        out[k] = refine_to_field_kernel(view, mine, poses[k:k + 1], inlier, refine)[0]
    return out


def split(refine: tuple, prune_after: int) -> tuple[tuple, tuple, bool]:
    """The compiled refinement's tuple cut at ``prune_after`` iterations into the parts before
    and after the pruning (neither pruning itself), and whether there is a part after. The
    returns' depth behind the walls starts anew in the second part; with the default gates it
    starts there anyway (below ``offset_gate``)."""
    gates = refine[0]
    cut = prune_after if 0 < prune_after < len(gates) else len(gates)
    first = (np.ascontiguousarray(gates[:cut]), refine[1], refine[2], 0) + refine[4:]
    second = (np.ascontiguousarray(gates[cut:]), refine[1], refine[2], 0) + refine[4:]
    return first, second, cut < len(gates)


def refine_each_to_field(map_: Map, laser: LaserSpec, ranges: np.ndarray, field: MapView,
                         poses: np.ndarray, config: RefineConfig, gate: float, min_returns: int,
                         groups: np.ndarray,
                         cost: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """``(K, 3)`` world poses refined against the map on the returns of ``ranges`` (metres) but
    the unmapped ones (see the module docstring; ``groups``:
    :func:`tfloc.tfplus.cost.object_groups`), pruned after ``prune_after`` iterations to the
    ``keep`` of lowest ``cost`` (the selection's, metres²): ``(K', 3)``."""
    poses = np.array(poses, dtype=float).reshape(-1, 3)
    view = (field.nearest, float(field.origin[0]), float(field.origin[1]), field.resolution,
            field.points, field.normals)
    points = laser.to_points(ranges)
    first, second, more = split(field_refinement(field, config), config.prune_after)

    def each(poses: np.ndarray, part: tuple) -> np.ndarray:
        short = unmapped(short_beams(map_, laser, ranges, poses, gate), groups)
        return refine_each_kernel(view, points, np.asarray(ranges, dtype=float), poses,
                                  float(config.inlier_distance), part, short,
                                  float(laser.max_range), int(min_returns), float(gate))

    poses = each(poses, first)
    if more:
        if len(poses) > config.keep:
            poses = poses[prune_index_kernel(poses, cost(poses), config.keep, 0.05)]
        poses = each(poses, second)
    return poses
