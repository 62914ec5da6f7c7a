"""``VectorMap``: walls and obstacles as line segments, with a compiled virtual sensor."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from tfloc.core.laser import LaserSpec
from tfloc.core.map import as_pose_array
from tfloc.core.pose import Pose

from ._raycast import raycast_segments
from .inside import Rings
from .segment_index import build_index


def _segments_of(geom: BaseGeometry) -> np.ndarray:
    """All straight pieces of a geometry's lines and polygon rings, shape ``(M, 4)``."""
    lines = shapely.get_parts(shapely.boundary(geom) if geom.geom_type.endswith("Polygon") else geom)
    segs = []
    for line in np.atleast_1d(lines):
        c = shapely.get_coordinates(line)
        if len(c) >= 2:
            segs.append(np.hstack((c[:-1], c[1:])))
    return np.vstack(segs) if segs else np.empty((0, 4))


@dataclass(frozen=True, eq=False)
class VectorMap:
    """A polygonal map in metres (the paper's "static and polygonal" environment).

    Attributes:
        walls: wall geometries (LineStrings) that reflect beams.
        obstacles: polygons that reflect beams and are not free space inside.
        outline: the mapped area (free space = outline − obstacles − walls); its boundary
            reflects beams.
        region: a mapped area that does not reflect beams, used when there is no outline (e.g.
            the surroundings of a reference scan); if both are ``None``, the convex hull of all
            geometry.
        name: a label for reports.
    """

    walls: tuple[BaseGeometry, ...] = ()
    obstacles: tuple[BaseGeometry, ...] = ()
    outline: BaseGeometry | None = None
    name: str = "map"
    region: BaseGeometry | None = None
    _free_cache: dict = field(default_factory=dict, repr=False)

    @classmethod
    def from_segments(cls, segments: np.ndarray, name: str = "segments",
                      region: BaseGeometry | None = None) -> VectorMap:
        """A map of bare wall segments ``(M, 4)`` = (ax, ay, bx, by), e.g. a reference scan polyline."""
        s = np.asarray(segments, dtype=float).reshape(-1, 4)
        return cls(walls=tuple(shapely.linestrings(s.reshape(-1, 2, 2))), name=name, region=region)

    @cached_property
    def segments(self) -> np.ndarray:
        """Every reflecting straight segment, ``(M, 4)`` float64, C-contiguous."""
        parts = [_segments_of(g) for g in (*self.walls, *self.obstacles)]
        if self.outline is not None:
            parts.append(_segments_of(self.outline))
        segs = np.vstack(parts) if parts else np.empty((0, 4))
        keep = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]) > 1e-12
        return np.ascontiguousarray(segs[keep])

    def segment_index(self, max_range: float) -> tuple:
        """The segments' buckets for casts of ``max_range`` metres
        (:func:`tfloc.maps.segment_index.build_index`; built once per range; ``NO_INDEX`` on a
        small map)."""
        key = ("segment-index", round(float(max_range), 9))
        if key not in self._free_cache:
            self._free_cache[key] = build_index(self.segments, max_range)
        return self._free_cache[key]

    @cached_property
    def area(self) -> BaseGeometry:
        """The mapped area: ``outline``, else ``region``, else the convex hull of all geometry."""
        if self.outline is not None:
            return self.outline
        if self.region is not None:
            return self.region
        return shapely.convex_hull(shapely.GeometryCollection([*self.walls, *self.obstacles]))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        xs, ys = self.segments[:, [0, 2]], self.segments[:, [1, 3]]
        return float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max())

    def raycast(self, poses: Pose | np.ndarray, laser: LaserSpec) -> np.ndarray:
        """Virtual sensor (VSD) for one pose → ``(n_beams,)`` or ``(N, 3)`` poses → ``(N, n_beams)``.

        Metres; ``inf`` where no segment is hit before ``laser.max_range``.
        """
        arr, single = as_pose_array(poses)
        r = raycast_segments(np.ascontiguousarray(arr), np.asarray(laser.angles, dtype=float),
                             self.segments, float(laser.max_range),
                             self.segment_index(float(laser.max_range)))
        return r[0] if single else r

    def _free_space(self, clearance: float) -> BaseGeometry:
        key = round(float(clearance), 9)
        if key not in self._free_cache:
            free = self.area
            if self.obstacles:
                free = free.difference(shapely.union_all(self.obstacles))
            if clearance > 0:
                free = free.difference(shapely.union_all(
                    [shapely.buffer(g, clearance) for g in (*self.walls, *self.obstacles)]
                    + ([shapely.boundary(self.outline).buffer(clearance)] if self.outline else [])))
            shapely.prepare(free)
            self._free_cache[key] = free
        return self._free_cache[key]

    def _rings(self, key: object, geom: BaseGeometry, build: bool) -> Rings | None:
        """The compiled point-in-area test of ``geom`` (:mod:`tfloc.maps.inside`): made when asked
        to ``build`` it (once), else ``None`` until then (the queries then go to shapely). It pays
        only for a map queried many times (its raster costs more than a few shapely calls), so
        a matcher builds it in ``prepare`` or for its own many queries, never a map used once."""
        if key not in self._free_cache:
            if not build:
                return None
            self._free_cache[key] = Rings.of(geom)
        return self._free_cache[key]

    def free_rings(self, clearance: float = 0.0, build: bool = False) -> Rings | None:
        """The compiled test behind :meth:`is_free` (``None``: not built, or shapely answers),
        for callers that run it inside their own compiled code; ``build`` makes it."""
        return self._rings(("rings", round(float(clearance), 9)), self._free_space(clearance), build)

    def area_rings(self, build: bool = False) -> Rings | None:
        """The compiled test behind :meth:`in_bounds` (see :meth:`free_rings`)."""
        return self._rings("area-rings", self.area, build)

    def is_free(self, xy: np.ndarray, clearance: float = 0.0) -> np.ndarray:
        """Which ``(N, 2)`` points are in free space at least ``clearance`` metres from geometry
        (shapely's ``contains_xy``; answered by the compiled :class:`~tfloc.maps.inside.Rings`
        once built, which defers to shapely near the boundary)."""
        p = np.asarray(xy, dtype=float).reshape(-1, 2)
        rings = self.free_rings(clearance)
        if rings is not None:
            return rings.contains(p, boundary=False)
        return shapely.contains_xy(self._free_space(clearance), p[:, 0], p[:, 1])

    def in_bounds(self, xy: np.ndarray) -> np.ndarray:
        """Which ``(N, 2)`` points lie inside the mapped area (boundary included; shapely's
        ``intersects_xy``, answered as :meth:`is_free` is)."""
        p = np.asarray(xy, dtype=float).reshape(-1, 2)
        rings = self.area_rings()
        if rings is not None:
            return rings.contains(p, boundary=True)
        area = self.area
        shapely.prepare(area)
        return shapely.intersects_xy(area, p[:, 0], p[:, 1])

    def sample_points(self, spacing: float) -> tuple[np.ndarray, np.ndarray]:
        """Points every ``spacing`` metres along every segment, with unit normals; ``(M, 2)`` each."""
        s = self.segments
        a, e = s[:, :2], s[:, 2:] - s[:, :2]
        length = np.hypot(e[:, 0], e[:, 1])
        n = np.maximum(1, np.ceil(length / spacing).astype(int))
        idx = np.repeat(np.arange(len(s)), n)
        start = np.repeat(np.cumsum(n) - n, n)
        frac = (np.arange(idx.size) - start + 0.5) / n[idx]
        pts = a[idx] + frac[:, None] * e[idx]
        unit = e / length[:, None]
        normals = np.column_stack((-unit[:, 1], unit[:, 0]))[idx]
        return pts, normals
