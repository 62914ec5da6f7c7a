"""Per-map caches of derived geometry (sampled points, KD-trees, likelihood fields).

A worker reuses one map object for many scans, so anything built from the map alone is built once.
Entries live as long as the map object (weak keys); maps that cannot be weakly referenced are
cached by identity with a strong reference, so an ``id`` is never reused for a different map.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
from scipy.spatial import cKDTree

from tfloc.core.pose import Pose

T = TypeVar("T")

_weak: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_strong: dict[int, tuple[Any, dict]] = {}


def _slot(map_: Any) -> dict:
    try:
        return _weak.setdefault(map_, {})
    except TypeError:
        entry = _strong.setdefault(id(map_), (map_, {}))
        return entry[1]


def cached(map_: Any, key: Hashable, build: Callable[[], T]) -> T:
    """The value for ``(map_, key)``, built with ``build()`` on first use."""
    slot = _slot(map_)
    if key not in slot:
        slot[key] = build()
    return slot[key]


@dataclass(frozen=True, eq=False)
class MapGeometry:
    """The map's geometry as points every ``spacing`` metres with unit normals and a KD-tree.

    Attributes:
        points: ``(M, 2)`` metres, world frame.
        normals: ``(M, 2)`` unit in-plane normals.
        tree: a ``cKDTree`` over ``points``.
        spacing: the sampling step, metres.
    """

    points: np.ndarray
    normals: np.ndarray
    tree: cKDTree
    spacing: float

    def near(self, center: Pose, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Points and normals within ``radius`` metres of ``center``'s position."""
        idx = self.tree.query_ball_point((center.x, center.y), radius)
        idx = np.sort(np.asarray(idx, dtype=int))
        return self.points[idx], self.normals[idx]


def map_geometry(map_: Any, spacing: float) -> MapGeometry:
    """The cached :class:`MapGeometry` of ``map_`` sampled every ``spacing`` metres."""

    def build() -> MapGeometry:
        pts, nrm = map_.sample_points(spacing)
        pts = np.ascontiguousarray(pts, dtype=float)
        return MapGeometry(pts, np.ascontiguousarray(nrm, dtype=float), cKDTree(pts), float(spacing))

    return cached(map_, ("geometry", round(float(spacing), 9)), build)


def point_to_line_residuals(geom: MapGeometry, world_points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each ``(N, 2)`` world point: its distance to the nearest map sample and its
    point-to-line residual ``|n · (p − q)|`` against that sample's normal (metres)."""
    d, idx = geom.tree.query(world_points)
    diff = world_points - geom.points[idx]
    return d, np.abs(np.einsum("ij,ij->i", diff, geom.normals[idx]))
