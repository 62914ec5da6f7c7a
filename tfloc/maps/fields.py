"""A truncated distance field of a map: the cheap, smooth objective of ``tf-plus``'s coarse search.

Built once per map from :meth:`Map.sample_points` (so it works for any map, vector or grid): the
map's points are rasterised at ``resolution`` metres and a Euclidean distance transform
(``scipy.ndimage.distance_transform_edt``) gives, in every cell, the distance (metres) to the
nearest map point, truncated at ``truncation``. Scoring a pose is then one table look-up per scan
point, so thousands of candidate poses cost a few milliseconds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import distance_transform_edt

from .base import Map


@dataclass(frozen=True, eq=False)
class DistanceField:
    """Distance (metres) to the nearest map point on a grid.

    Attributes:
        origin: world ``(x, y)`` of cell ``(0, 0)``'s lower-left corner (metres).
        resolution: cell size (metres).
        table: ``(ny, nx)`` distances (metres), truncated at ``truncation``.
        truncation: the value of far and off-grid points (metres).
    """

    origin: np.ndarray
    resolution: float
    table: np.ndarray
    truncation: float

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Distance at world points ``(..., 2)`` (nearest cell; ``truncation`` off the grid, via the
        border cells that clipped indices land on)."""
        ny, nx = self.table.shape
        ix = np.clip(((xy[..., 0] - self.origin[0]) / self.resolution).astype(np.int64), 0, nx - 1)
        iy = np.clip(((xy[..., 1] - self.origin[1]) / self.resolution).astype(np.int64), 0, ny - 1)
        return self.table.ravel()[iy * nx + ix]


def distance_field(map_: Map, resolution: float = 0.05, truncation: float = 0.5) -> DistanceField:
    """The truncated distance field of ``map_`` (metres), with a ``truncation`` margin around it."""
    pts, _ = map_.sample_points(resolution / 2.0)
    xmin, ymin, xmax, ymax = map_.bounds
    margin = truncation + 2 * resolution
    origin = np.array([xmin - margin, ymin - margin])
    nx = int(np.ceil((xmax - xmin + 2 * margin) / resolution)) + 1
    ny = int(np.ceil((ymax - ymin + 2 * margin) / resolution)) + 1
    occupied = np.zeros((ny, nx), dtype=bool)
    ij = np.floor((pts - origin) / resolution).astype(np.int64)
    occupied[np.clip(ij[:, 1], 0, ny - 1), np.clip(ij[:, 0], 0, nx - 1)] = True
    dist = np.minimum(distance_transform_edt(~occupied) * resolution, truncation)
    dist[[0, -1], :] = truncation      # the border holds every off-grid look-up (clipped)
    dist[:, [0, -1]] = truncation
    return DistanceField(origin, resolution, dist.astype(np.float32), truncation)
