"""``tf-plus``'s view of a map: the map's distance field with each cell's nearest map point
(:mod:`tfloc.maps.fields`), and on a grid map each point's distance to its wall's two surfaces
(:mod:`tfloc.maps.walls`). Built once per map (:mod:`tfloc.maps.cache`).

Why the map's own points, and not a ray-cast virtual scan: a grid map built from real scans draws
walls several cells thick (the scans' registration error, range noise), and a ray stops at the
first occupied cell, so the virtual scan is short, the more so the thicker the walls are drawn
(measured: ``docs/tf-plus.md``, "Real logs"). A return lies *inside* the wall it hit; the walls
are followed across so that a return can be measured from the wall's surface. On a vector map
the nearest sample point lies on the wall's line, its normal is the wall's, and walls have no
thickness.

The attribute names are those the compiled kernels take (``tfloc.tfplus.*_kernel``): ``table``
(distances, metres), ``origin`` (the outer corner of cell ``(0, 0)``), ``resolution``,
``points``/``normals``/``nearest``, ``face_plus``/``face_minus``, ``faces``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from tfloc.core.map import Map
from tfloc.maps.cache import cached
from tfloc.maps.fields import DistanceField, distance_field, pooled
from tfloc.maps.grid import GridMap
from tfloc.maps.walls import run_extents


@dataclass(frozen=True, eq=False)
class MapView:
    """The field (with nearest points) and, per map point, how far (metres) its wall's surface
    lies along ``+normal`` (``face_plus``) and ``−normal`` (``face_minus``); both 0 and
    ``faces`` false where walls have no thickness (a vector map)."""

    field: DistanceField
    face_plus: np.ndarray
    face_minus: np.ndarray
    faces: bool

    @property
    def table(self) -> np.ndarray:
        return self.field.distance

    @property
    def origin(self) -> np.ndarray:
        return np.asarray(self.field.corner)

    @property
    def resolution(self) -> float:
        return self.field.resolution

    @property
    def points(self) -> np.ndarray:
        return self.field.points

    @property
    def normals(self) -> np.ndarray:
        return self.field.normals

    @property
    def nearest(self) -> np.ndarray:
        return self.field.nearest

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Distance (metres) at world points ``(..., 2)``."""
        return self.field(xy)


def map_view(map_: Map, resolution: float, truncation: float, wall_thickness: float,
             pool: float = 0.0, free_cap: float | None = None) -> MapView:
    """The view of ``map_`` (field cells of ``resolution``, distances truncated at ``truncation``,
    walls followed up to ``wall_thickness`` metres across on a grid map), built once per map; with
    ``pool`` > 0 its distances are pooled over ± ``pool`` metres (a lower bound over that square,
    :func:`tfloc.maps.fields.pooled`, for the coarse search); with ``free_cap`` (metres) capped
    there in the map's free space (:func:`free_capped`)."""
    key = ("tf-plus-view", round(resolution, 9), round(truncation, 9), round(wall_thickness, 9),
           round(pool, 9), None if free_cap is None else round(free_cap, 9))
    if free_cap is not None:
        base = map_view(map_, resolution, truncation, wall_thickness, pool)
        return cached(map_, key, lambda: free_capped(map_, base, free_cap))
    if pool > 0:
        base = map_view(map_, resolution, truncation, wall_thickness)
        return cached(map_, key, lambda: MapView(pooled(base.field, pool), base.face_plus,
                                                base.face_minus, base.faces))

    def build() -> MapView:
        f = distance_field(map_, resolution, truncation, nearest=True)
        faces = isinstance(map_, GridMap) and wall_thickness > 0 and len(f.points) > 0
        if not faces:
            zero = np.zeros(len(f.points))
            return MapView(f, zero, zero, False)
        half_step = map_.resolution / 6.0     # the surface lies half a walking step beyond the run
        plus, minus = run_extents(f.points, f.normals, map_.occupied, np.asarray(map_.origin),
                                  map_.resolution, wall_thickness)
        return MapView(f, np.ascontiguousarray(plus + half_step),
                       np.ascontiguousarray(minus + half_step), True)

    return cached(map_, key, build)



def free_capped(map_: Map, view: MapView, cap: float) -> MapView:
    """``view`` with every cell whose centre lies in the map's known free space (``in_bounds``
    and ``is_free``) holding at most ``cap`` metres.

    Why: a scan point far from every wall is a wrong pose's point *or* a return from an object
    the map lacks (a person, a cart) standing in free space; the coarse search cannot tell the
    two apart without a ray per point, and the full penalty for both lets a quarter of the beams
    on unmapped objects push the true pose out of the shortlist. A point outside free space (in
    an obstacle, in unknown space, outside the building) keeps its full distance: no unmapped
    object explains it (measured: ``docs/robustness.md``)."""
    table = view.table
    h, w = table.shape
    x0, y0 = view.field.origin                      # the centre of cell (0, 0)
    res = view.resolution
    gx, gy = np.meshgrid(x0 + res * np.arange(w), y0 + res * np.arange(h))
    xy = np.column_stack((gx.ravel(), gy.ravel()))
    free = np.zeros(len(xy), dtype=bool)
    inside = map_.in_bounds(xy)
    free[inside] = map_.is_free(xy[inside])
    capped = np.where(free.reshape(h, w), np.minimum(table, table.dtype.type(cap)), table)
    return MapView(replace(view.field, distance=np.ascontiguousarray(capped, dtype=table.dtype)),
                   view.face_plus, view.face_minus, view.faces)
