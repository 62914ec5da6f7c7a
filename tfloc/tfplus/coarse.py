"""Coarse pose search of ``tf-plus``: a grid over positions × a few headings, on a distance field.

Positions lie on a square lattice within ``radius`` metres of the initial guess (only those in
free space); each is tried with every given heading. A candidate's score is the mean truncated
distance (metres) of the real scan's points, placed at that pose, to the nearest map point
(:class:`~tfloc.maps.fields.DistanceField`), one table look-up per point: first on a subset
of the points for every candidate, then on all points for a shortlist. The best few candidates,
at least ``separation`` metres apart, are returned for refinement.
"""

from __future__ import annotations

import numpy as np

from tfloc.core.map import Map
from tfloc.maps.fields import DistanceField

from .kernels import grid_scores_kernel


def lattice(map_: Map, field: DistanceField, centre: np.ndarray, radius: float, step: float,
            clearance: float) -> np.ndarray:
    """Free lattice positions ``(N, 2)`` (metres) within ``radius`` of ``centre``, centre first,
    at least ``clearance`` from the map's points (by the distance field: a clearance query to
    the map itself can cost more than the whole search on a map used once)."""
    k = int(np.floor(radius / step))
    g = np.arange(-k, k + 1) * step
    gx, gy = np.meshgrid(g, g)
    off = np.column_stack((gx.ravel(), gy.ravel()))
    off = off[np.hypot(off[:, 0], off[:, 1]) <= radius + 1e-9]
    off = off[np.argsort(np.hypot(off[:, 0], off[:, 1]), kind="stable")]
    xy = centre[None, :] + off
    keep = field(xy) >= clearance
    keep[keep] = map_.in_bounds(xy[keep])
    keep[keep] = map_.is_free(xy[keep])
    return xy[keep]


def grid_scores(field: DistanceField, points: np.ndarray, positions: np.ndarray,
                headings: np.ndarray) -> np.ndarray:
    """Mean distance-field value ``(N, H)`` of ``points`` ``(M, 2)`` at every position × heading."""
    cx, cy = field.corner
    return grid_scores_kernel(field.distance, float(cx), float(cy),
                              field.resolution, np.ascontiguousarray(points, dtype=float),
                              np.ascontiguousarray(positions, dtype=float),
                              np.ascontiguousarray(headings, dtype=float))


def pose_scores(field: DistanceField, points: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Mean distance-field value ``(N,)`` of ``points`` ``(M, 2)`` at each of ``(N, 3)`` poses."""
    c, s = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
    wx = poses[:, :1] + c * points[None, :, 0] - s * points[None, :, 1]
    wy = poses[:, 1:2] + s * points[None, :, 0] + c * points[None, :, 1]
    return field(np.stack((wx, wy), axis=-1)).mean(axis=-1)


def search(field: DistanceField, points: np.ndarray, positions: np.ndarray, headings: np.ndarray,
           stride: int, shortlist: int) -> tuple[np.ndarray, np.ndarray]:
    """Two-level grid search: every position × heading on every ``stride``-th point, then the best
    ``shortlist`` of them on all points. Returns those poses ``(S, 3)`` and their scores ``(S,)``."""
    coarse = grid_scores(field, points[::stride], positions, headings).ravel()
    if shortlist < coarse.size:
        top = np.argpartition(coarse, shortlist)[:shortlist]
    else:
        top = np.arange(coarse.size)
    poses = np.column_stack((positions[top // len(headings)], headings[top % len(headings)]))
    return poses, pose_scores(field, points, poses)


def best_candidates(poses: np.ndarray, scores: np.ndarray, count: int,
                    separation: float) -> np.ndarray:
    """Up to ``count`` of ``(N, 3)`` poses of lowest score, positions ≥ ``separation`` apart."""
    order = poses[np.argsort(scores, kind="stable")]
    keep = [0]
    for i in range(1, len(order)):
        d = np.hypot(*(order[keep, :2] - order[i, :2]).T)
        if d.min() >= separation:
            keep.append(i)
            if len(keep) == count:
                break
    return order[keep[:count]].reshape(-1, 3)
