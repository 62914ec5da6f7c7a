"""A truncated distance field of a map, with each cell's nearest map point: ``tf-plus``'s view of the map.

Built once per map from :meth:`Map.sample_points` (so it works for any map, vector or grid): the
map's points are rasterised at ``resolution`` metres and a Euclidean distance transform
(``scipy.ndimage.distance_transform_edt``) gives, in every cell, the distance (metres) to the
nearest map point, truncated at ``truncation``, and which map point that is. Scoring a pose is
then one table look-up per scan point, so thousands of candidate poses cost a few milliseconds
(the coarse search, :mod:`tfloc.coarse`); and the nearest map point with its normal turns every
scan point into a point-to-line pair without simulating a scan (the refinement and the selection
cost, :mod:`tfloc.refine`, :mod:`tfloc.scan_cost`).

Why the map's own points on a grid, and not a ray-cast virtual scan: a grid map built from real
scans draws walls several cells thick (the scans' registration error, range noise), and a ray
stops at the first occupied cell, so the virtual scan is short (measured at the true poses:
median −1.5 cm on the Intel grid, −7.9 and −14.2 cm on it with the walls thickened by one and
two cells). A return lies *inside* the wall it hit; the grid's walls are also followed across
(:mod:`tfloc.wall_faces`) so that a return can be measured from the wall's surface. On a vector
map the nearest sample point lies on the wall's line and its normal is the wall's.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.ndimage import distance_transform_edt, minimum_filter

from .maps.base import Map
from .maps.grid import GridMap
from .wall_faces import run_extents


@dataclass(frozen=True, eq=False)
class DistanceField:
    """Distance (metres) to the nearest map point on a grid.

    Attributes:
        origin: world ``(x, y)`` of cell ``(0, 0)``'s lower-left corner (metres).
        resolution: cell size (metres).
        table: ``(ny, nx)`` distances (metres), truncated at ``truncation``.
        truncation: the value of far and off-grid points (metres).
        points: ``(M, 2)`` the map's sample points (metres) ...
        normals: ``(M, 2)`` ... and their unit normals.
        nearest: ``(ny, nx)`` int32, the index into ``points`` of each cell's nearest map point
            (by cell; the border cells, where off-grid look-ups land, hold it too).
        face_plus: ``(M,)`` distance (metres) from each point to its wall's surface along
            ``+normal`` ...
        face_minus: ``(M,)`` ... and along ``−normal`` (on a grid map, where the run of occupied
            cells through the point ends; 0 on a vector map, whose walls have no thickness).
        faces: whether the map's walls have thickness (a grid map).
    """

    origin: np.ndarray
    resolution: float
    table: np.ndarray
    truncation: float
    points: np.ndarray
    normals: np.ndarray
    nearest: np.ndarray
    face_plus: np.ndarray
    face_minus: np.ndarray
    faces: bool

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Distance at world points ``(..., 2)`` (nearest cell; ``truncation`` off the grid, via the
        border cells that clipped indices land on)."""
        ny, nx = self.table.shape
        ix = np.clip(((xy[..., 0] - self.origin[0]) / self.resolution).astype(np.int64), 0, nx - 1)
        iy = np.clip(((xy[..., 1] - self.origin[1]) / self.resolution).astype(np.int64), 0, ny - 1)
        return self.table.ravel()[iy * nx + ix]


def distance_field(map_: Map, resolution: float = 0.05, truncation: float = 0.5,
                   wall_thickness: float = 0.0) -> DistanceField:
    """The truncated distance field of ``map_`` (metres), with a ``truncation`` margin around it,
    and each cell's nearest map point (sampled every ``resolution / 2``; on a grid map every
    occupied cell's centre). On a grid map, each point's distances to its wall's two surfaces
    (where the run of occupied cells along its normal ends, followed up to ``wall_thickness``
    metres, :func:`tfloc.wall_faces.run_extents`); a vector map's walls have no thickness."""
    pts, normals = map_.sample_points(resolution / 2.0)
    faces = isinstance(map_, GridMap) and wall_thickness > 0 and len(pts) > 0
    if faces:
        step = map_.resolution / 3.0
        plus, minus = run_extents(pts, normals, map_.occupied, np.asarray(map_.origin),
                                  map_.resolution, wall_thickness)
        plus, minus = plus + step / 2, minus + step / 2
    else:
        plus = minus = np.zeros(len(pts))
    xmin, ymin, xmax, ymax = map_.bounds
    margin = truncation + 2 * resolution
    origin = np.array([xmin - margin, ymin - margin])
    nx = int(np.ceil((xmax - xmin + 2 * margin) / resolution)) + 1
    ny = int(np.ceil((ymax - ymin + 2 * margin) / resolution)) + 1
    occupied = np.zeros((ny, nx), dtype=bool)
    ij = np.floor((pts - origin) / resolution).astype(np.int64)
    iy, ix = np.clip(ij[:, 1], 0, ny - 1), np.clip(ij[:, 0], 0, nx - 1)
    occupied[iy, ix] = True
    owner = np.full((ny, nx), -1, dtype=np.int32)      # one map point per occupied cell
    owner[iy, ix] = np.arange(len(pts), dtype=np.int32)
    if len(pts):
        edt, (ny_idx, nx_idx) = distance_transform_edt(~occupied, return_indices=True)
        nearest = owner[ny_idx, nx_idx]
    else:
        edt, nearest = np.full((ny, nx), np.inf), owner
    dist = np.minimum(edt * resolution, truncation)
    dist[[0, -1], :] = truncation      # the border holds every off-grid look-up (clipped)
    dist[:, [0, -1]] = truncation
    return DistanceField(origin, resolution, dist.astype(np.float32), truncation,
                         np.ascontiguousarray(pts, dtype=float), np.ascontiguousarray(normals, dtype=float),
                         np.ascontiguousarray(nearest, dtype=np.int32),
                         np.ascontiguousarray(plus, dtype=float), np.ascontiguousarray(minus, dtype=float),
                         bool(faces))


def pooled(field: DistanceField, half_width: float) -> DistanceField:
    """``field`` with every cell's distance replaced by the smallest within ``± half_width`` metres
    (in x and y): a lower bound of the distance at any point that far from where it is looked up,
    so a pose's score on it bounds from below the score of every translation within that square
    (Olson's low-resolution table, for distances)."""
    k = int(round(half_width / field.resolution))
    if k < 1:
        return field
    return replace(field, table=minimum_filter(field.table, size=2 * k + 1, mode="nearest"))
