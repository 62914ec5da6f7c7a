"""The distance field of a map: distance (metres) to the nearest map geometry on a regular grid.

One field serves every matcher that scores scan points by their distance to the map: ``tf-plus``'s
coarse search (nearest-cell look-ups, thousands of candidate poses in a few milliseconds) and
``csm-corr``'s likelihood field and refinement (:mod:`tfloc.baselines.likelihood`, bilinear look-ups).
It is built from :meth:`Map.sample_points`, so it works for any map, vector or grid: the map's
points (every ``resolution/2`` metres) are rasterised to their nearest cell centre and a Euclidean
distance transform (``scipy.ndimage.distance_transform_edt``, :func:`edt_metres`) gives every cell
centre its distance to the nearest such cell, capped at ``cap``; on request
(``nearest=True``) also which map point that is, with the point's normal, so that a scan point
becomes a point-to-line pair by one look-up (``tf-plus``'s refinement on grid maps). Cell centres
lie on the map's own lattice (:func:`lattice_anchor`): a raster map's cell centres, else the
lattice ``(xmin, ymin) + k·resolution`` of the map's bounds. The grid reaches ``cap`` (plus a
cell) and then ``pad`` metres beyond the bounds, so its border cells hold ``cap``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.ndimage import distance_transform_edt, map_coordinates, minimum_filter

from tfloc.core.map import Map

from .cache import cached


def edt_metres(free: np.ndarray, resolution: float) -> np.ndarray:
    """Distance (metres) from every cell centre to the nearest cell that is not ``free``
    (the one distance transform of tfloc)."""
    return distance_transform_edt(free) * resolution


@dataclass(frozen=True, eq=False)
class DistanceField:
    """Distance (metres) to the nearest map point at the centres of a grid.

    Attributes:
        distance: ``(H, W)`` float32 metres, row = y index, column = x index, at most ``cap``.
        origin: world ``(x, y)`` of the centre of cell ``[0, 0]`` (metres).
        resolution: cell size (metres).
        cap: the distance of every far cell, and of look-ups off the grid (metres).
        points: ``(M, 2)`` the map's sample points (metres), with ``nearest=True`` ...
        normals: ``(M, 2)`` ... their unit normals ...
        nearest: ``(H, W)`` int32 ... and the index into ``points`` of each cell's nearest map
            point (border cells, where off-grid look-ups land, hold it too).
    """

    distance: np.ndarray
    origin: tuple[float, float]
    resolution: float
    cap: float
    points: np.ndarray | None = None
    normals: np.ndarray | None = None
    nearest: np.ndarray | None = None

    @property
    def shape(self) -> tuple[int, int]:
        return self.distance.shape  # type: ignore[return-value]

    @property
    def corner(self) -> tuple[float, float]:
        """World ``(x, y)`` of the outer corner of cell ``[0, 0]`` (metres)."""
        h = 0.5 * self.resolution
        return self.origin[0] - h, self.origin[1] - h

    def cells(self, xy: np.ndarray) -> np.ndarray:
        """Nearest integer cell ``(..., 2)`` = (column, row) of world points ``(..., 2)``."""
        return np.rint((np.asarray(xy) - self.origin) / self.resolution).astype(np.int64)

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Distance at world points ``(..., 2)``: the cell containing each point; points off the
        grid get the border cell's value, which is ``cap`` when ``pad`` ≥ ``cap``."""
        h, w = self.shape
        cx, cy = self.corner
        ix = np.clip(np.floor((xy[..., 0] - cx) / self.resolution).astype(np.int64), 0, w - 1)
        iy = np.clip(np.floor((xy[..., 1] - cy) / self.resolution).astype(np.int64), 0, h - 1)
        return self.distance.ravel()[iy * w + ix]

    def interpolate(self, xy: np.ndarray) -> np.ndarray:
        """Bilinearly interpolated distance (metres) at world points ``(N, 2)``."""
        g = (np.asarray(xy, dtype=float) - self.origin) / self.resolution
        return map_coordinates(self.distance, (g[:, 1], g[:, 0]), order=1, mode="nearest")


def lattice_anchor(map_: Map, resolution: float) -> np.ndarray:
    """A point of the lattice of field cell centres (metres): the map's lower bounds, except on a
    raster map (one with ``occupied`` cells, a ``resolution`` and an ``origin``, e.g. a
    :class:`~tfloc.maps.grid.GridMap`) whose cells are an odd number of field cells wide: there
    its first cell's centre. Either way the raster's sample points (its occupied cells' centres)
    never fall on a border between two field cells, where rounding would shift the whole map by
    half a field cell, a bias every refinement on the field would inherit."""
    x0, y0 = map_.bounds[:2]
    if hasattr(map_, "occupied") and hasattr(map_, "origin") and hasattr(map_, "resolution"):
        k = float(map_.resolution) / resolution
        if abs(k - round(k)) < 1e-9 and round(k) % 2 == 1:
            return np.asarray(map_.origin, dtype=float) + 0.5 * float(map_.resolution)
    return np.array([x0, y0], dtype=float)


def build_distance_field(map_: Map, resolution: float, cap: float, pad: float,
                         nearest: bool = False) -> DistanceField:
    """Rasterise ``map_`` into a :class:`DistanceField` (metres): cells ``resolution``, values
    capped at ``cap``, the grid ``cap`` + one cell + ``pad`` metres beyond the map's bounds;
    with ``nearest``, each cell's nearest map point too (of the points rasterised to one cell,
    the last)."""
    x0, y0, x1, y1 = map_.bounds
    ax, ay = lattice_anchor(map_, resolution)
    x0, y0 = ax - np.ceil((ax - x0) / resolution) * resolution, ay - np.ceil((ay - y0) / resolution) * resolution
    pts, normals = map_.sample_points(resolution / 2.0)
    m = int(math.ceil(cap / resolution)) + 1        # beyond m cells every distance exceeds cap
    p = int(math.ceil(pad / resolution))
    w_in = int(math.ceil((x1 - x0) / resolution)) + 1 + 2 * m
    h_in = int(math.ceil((y1 - y0) / resolution)) + 1 + 2 * m
    inner = np.array([x0, y0]) - m * resolution
    c = np.rint((pts - inner) / resolution).astype(np.int64)
    keep = (c[:, 0] >= 0) & (c[:, 0] < w_in) & (c[:, 1] >= 0) & (c[:, 1] < h_in)
    free = np.ones((h_in, w_in), dtype=bool)
    free[c[keep, 1], c[keep, 0]] = False
    origin = inner - p * resolution
    origin = (float(origin[0]), float(origin[1]))
    if not nearest:
        dist = np.minimum(edt_metres(free, resolution), cap).astype(np.float32)
        dist = np.pad(dist, p, mode="constant", constant_values=np.float32(cap))
        return DistanceField(dist, origin, float(resolution), float(cap))
    owner = np.full(free.shape, -1, dtype=np.int32)
    owner[c[keep, 1], c[keep, 0]] = np.flatnonzero(keep).astype(np.int32)
    if keep.any():
        edt, (iy, ix) = distance_transform_edt(free, return_indices=True)
        near = owner[iy, ix]
    else:
        edt, near = np.full(free.shape, np.inf), owner
    dist = np.pad(np.minimum(edt * resolution, cap).astype(np.float32), p, mode="constant",
                  constant_values=np.float32(cap))
    return DistanceField(dist, origin, float(resolution), float(cap),
                         np.ascontiguousarray(pts, dtype=float), np.ascontiguousarray(normals, dtype=float),
                         np.ascontiguousarray(np.pad(near, p, mode="edge"), dtype=np.int32))


def distance_field(map_: Map, resolution: float, cap: float, pad: float = 0.0,
                   nearest: bool = False) -> DistanceField:
    """The :func:`build_distance_field` of ``map_``, built once per map and parameters
    (:mod:`tfloc.maps.cache`)."""
    key = ("distance-field", round(resolution, 9), round(cap, 9), round(pad, 6), nearest)
    return cached(map_, key, lambda: build_distance_field(map_, resolution, cap, pad, nearest))


def pooled(field: DistanceField, half_width: float) -> DistanceField:
    """``field`` with every cell's distance replaced by the smallest within ``± half_width``
    metres (in x and y): a lower bound of the distance at any point that far from where it is
    looked up, so a pose's score on it bounds from below the score of every translation within
    that square (Olson's low-resolution table, for distances)."""
    k = int(round(half_width / field.resolution))
    if k < 1:
        return field
    return replace(field, distance=minimum_filter(field.distance, size=2 * k + 1, mode="nearest"))
