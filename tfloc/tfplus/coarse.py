"""Coarse pose search of ``tf-plus``: a grid over positions × a few headings, on a distance field.

Positions lie on a square lattice within ``radius`` metres of the initial guess (only those in
free space); each is tried with every given heading. A candidate's score is the mean truncated
distance (metres) of the real scan's points, placed at that pose, to the nearest map point
(:class:`~tfloc.tfplus.view.MapView`; ``tf-plus`` passes the field pooled over each
lattice cell, :func:`tfloc.tfplus.view.pooled`, so a lattice pose's score bounds those of
the translations around it), one table look-up per point: first on a subset of the points for
every candidate, then on all points for a shortlist. The best few candidates, at least
``separation`` metres apart, are returned for refinement.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from tfloc.core.map import Map
from tfloc.maps.grid import GridMap
from tfloc.maps.inside import SURE
from tfloc.maps.vector import VectorMap

from .coarse_kernel import (
    candidates_kernel,
    grid_lattice_kernel,
    lattice_kernel,
    pose_scores_kernel,
    separated_kernel,
)
from .view import MapView


def lattice(map_: Map, field: MapView, centre: np.ndarray, radius: float, step: float,
            clearance: float) -> np.ndarray:
    """Free lattice positions ``(N, 2)`` (metres) within ``radius`` of ``centre``, centre first,
    at least ``clearance`` from the map's points (by the distance field: a clearance query to
    the map itself can cost more than the whole search on a map used once)."""
    offsets = _offsets(float(radius), float(step))
    if isinstance(map_, VectorMap):            # the same tests in one compiled call (the field
        # compared in its own dtype, as numpy compares a float32 array with a Python float)
        area, free = map_.area_rings(), map_.free_rings()
        if area is not None and free is not None:
            corner = field.origin
            positions, decided = lattice_kernel(
                float(centre[0]), float(centre[1]), offsets, field.table, float(corner[0]),
                float(corner[1]), field.resolution, field.table.dtype.type(clearance),
                area.kernel, free.kernel, SURE)
            if decided:
                return positions
    if isinstance(map_, GridMap):
        corner = field.origin
        return grid_lattice_kernel(
            float(centre[0]), float(centre[1]), offsets, field.table, float(corner[0]),
            float(corner[1]), field.resolution, field.table.dtype.type(clearance),
            float(map_.origin[0]), float(map_.origin[1]), float(map_.resolution), map_.free,
            map_.distance, 0.5 * map_.resolution)
    xy = centre[None, :] + offsets
    keep = field(xy) >= clearance
    keep[keep] = map_.in_bounds(xy[keep])
    keep[keep] = map_.is_free(xy[keep])
    return xy[keep]


@lru_cache(maxsize=16)
def _offsets(radius: float, step: float) -> np.ndarray:
    """Lattice offsets ``(N, 2)`` (metres) within ``radius``, nearest first (read-only; they
    depend on the configuration only, so they are made once)."""
    k = int(np.floor(radius / step))
    g = np.arange(-k, k + 1) * step
    gx, gy = np.meshgrid(g, g)
    off = np.column_stack((gx.ravel(), gy.ravel()))
    off = off[np.hypot(off[:, 0], off[:, 1]) <= radius + 1e-9]
    off = off[np.argsort(np.hypot(off[:, 0], off[:, 1]), kind="stable")]
    off.setflags(write=False)
    return off


def pose_scores(field: MapView, points: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Mean distance-field value ``(N,)`` of ``points`` ``(M, 2)`` at each of ``(N, 3)`` poses."""
    return pose_scores_kernel(field.table, float(field.origin[0]), float(field.origin[1]),
                              field.resolution, np.ascontiguousarray(points, dtype=float),
                              np.ascontiguousarray(np.reshape(poses, (-1, 3)), dtype=float))


def candidates(field: MapView, points: np.ndarray, positions: np.ndarray, headings: np.ndarray,
               stride: int, shortlist: int, count: int, separation: float,
               step: float = 0.0) -> tuple[np.ndarray, np.ndarray, int]:
    """Two-level grid search: every position × heading on every ``stride``-th point, then the best
    ``shortlist`` of them on all points, of which up to ``count`` of lowest score at least
    ``separation`` metres apart are returned: ``(C, 3)`` poses, their scores ``(C,)`` and the
    number of poses rescored. ``step``: the spacing (metres) of the lattice the positions lie on
    (:func:`lattice`'s; 0 if none), which saves a cell index per look-up. One compiled call
    (:func:`~tfloc.tfplus.coarse_kernel.candidates_kernel`).

    The shortlist is ordered by the first level's score, ties for a place by lower index
    (position-major; :func:`~tfloc.tfplus.coarse_kernel.smallest_kernel`): the first level's
    scores are means of a few float32 distances of ~20 distinct values, so the last place is
    often tied (about one scan in five), and a rule of its own, rather than a selection
    algorithm's, decides which pose takes it."""
    return candidates_kernel(field.table, float(field.origin[0]), float(field.origin[1]),
                             field.resolution, np.ascontiguousarray(points, dtype=float),
                             int(stride), np.ascontiguousarray(positions, dtype=float),
                             np.ascontiguousarray(headings, dtype=float), int(shortlist),
                             int(count), float(separation), float(step))


def best_candidates(poses: np.ndarray, scores: np.ndarray, count: int,
                    separation: float) -> np.ndarray:
    """Up to ``count`` of ``(N, 3)`` poses of lowest score, positions ≥ ``separation`` apart."""
    order = np.ascontiguousarray(poses[np.argsort(scores, kind="stable")], dtype=float)
    return order[separated_kernel(order, count, separation)].reshape(-1, 3)
