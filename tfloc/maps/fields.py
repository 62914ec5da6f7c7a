"""The distance field of a map: distance (metres) to the nearest map geometry on a regular grid.

One field serves every matcher that scores scan points by their distance to the map: ``tf-plus``'s
coarse search (nearest-cell look-ups, thousands of candidate poses in a few milliseconds) and
``csm-corr``'s likelihood field and refinement (:mod:`tfloc.baselines.likelihood`, bilinear look-ups).
It is built from :meth:`Map.sample_points`, so it works for any map, vector or grid: the map's
points (every ``resolution/2`` metres) are rasterised to their nearest cell centre and a Euclidean
distance transform (``scipy.ndimage.distance_transform_edt``, :func:`edt_metres`) gives every cell
centre its distance to the nearest such cell, capped at ``cap``. Cell centres lie on the lattice
``(xmin, ymin) + k·resolution`` of the map's bounds; the grid reaches ``cap`` (plus a cell) and
then ``pad`` metres beyond them, so its border cells hold ``cap``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import distance_transform_edt, map_coordinates

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
    """

    distance: np.ndarray
    origin: tuple[float, float]
    resolution: float
    cap: float

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


def build_distance_field(map_: Map, resolution: float, cap: float, pad: float) -> DistanceField:
    """Rasterise ``map_`` into a :class:`DistanceField` (metres): cells ``resolution``, values
    capped at ``cap``, the grid ``cap`` + one cell + ``pad`` metres beyond the map's bounds."""
    x0, y0, x1, y1 = map_.bounds
    pts, _ = map_.sample_points(resolution / 2.0)
    m = int(math.ceil(cap / resolution)) + 1        # beyond m cells every distance exceeds cap
    p = int(math.ceil(pad / resolution))
    w_in = int(math.ceil((x1 - x0) / resolution)) + 1 + 2 * m
    h_in = int(math.ceil((y1 - y0) / resolution)) + 1 + 2 * m
    inner = np.array([x0, y0]) - m * resolution
    c = np.rint((pts - inner) / resolution).astype(np.int64)
    keep = (c[:, 0] >= 0) & (c[:, 0] < w_in) & (c[:, 1] >= 0) & (c[:, 1] < h_in)
    free = np.ones((h_in, w_in), dtype=bool)
    free[c[keep, 1], c[keep, 0]] = False
    dist = np.minimum(edt_metres(free, resolution), cap).astype(np.float32)
    dist = np.pad(dist, p, mode="constant", constant_values=np.float32(cap))
    origin = inner - p * resolution
    return DistanceField(dist, (float(origin[0]), float(origin[1])), float(resolution), float(cap))


def distance_field(map_: Map, resolution: float, cap: float, pad: float = 0.0) -> DistanceField:
    """The :func:`build_distance_field` of ``map_``, built once per map and parameters
    (:mod:`tfloc.maps.cache`)."""
    key = ("distance-field", round(resolution, 9), round(cap, 9), round(pad, 6))
    return cached(map_, key, lambda: build_distance_field(map_, resolution, cap, pad))
