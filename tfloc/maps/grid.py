"""``GridMap``: an occupancy grid (ROS map_server semantics) with a compiled virtual sensor."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy import ndimage

from tfloc.core.laser import LaserSpec
from tfloc.core.map import as_pose_array
from tfloc.core.pose import Pose
from tfloc.errors import MapFormatError

from ._gridcast import inside_kernel, raycast_grid
from .fields import edt_metres


@dataclass(frozen=True, eq=False)
class GridMap:
    """An occupancy grid in metres.

    Attributes:
        occupancy: ``(H, W)`` occupancy probability in [0, 1], NaN = unknown. Row ``j`` covers
            ``y ∈ [oy + j·res, oy + (j+1)·res)`` (row 0 is the *lowest* y, unlike an image),
            column ``i`` covers ``x ∈ [ox + i·res, ox + (i+1)·res)``.
        resolution: cell size (metres per cell).
        origin: ``(ox, oy)``, world position (m) of the outer corner of cell ``[0, 0]``.
        occupied_thresh: a cell with probability > this reflects beams (ROS semantics).
        free_thresh: a cell with probability < this is free space.
        name: a label for reports.
    """

    occupancy: np.ndarray
    resolution: float
    origin: tuple[float, float] = (0.0, 0.0)
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196
    name: str = "grid"

    def __post_init__(self) -> None:
        occ = np.asarray(self.occupancy, dtype=np.float32)
        if occ.ndim != 2 or occ.shape[0] < 1 or occ.shape[1] < 1:
            raise MapFormatError(f"{self.name}: occupancy must be a non-empty 2-D array, got shape {occ.shape}")
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            raise MapFormatError(f"{self.name}: resolution must be a positive number of metres, got {self.resolution!r}")
        if not (0.0 <= self.free_thresh <= self.occupied_thresh <= 1.0):
            raise MapFormatError(f"{self.name}: need 0 ≤ free_thresh ≤ occupied_thresh ≤ 1, got "
                                 f"{self.free_thresh}, {self.occupied_thresh}")
        with np.errstate(invalid="ignore"):
            if np.any((occ < 0) | (occ > 1)):
                raise MapFormatError(f"{self.name}: occupancy values must lie in [0, 1] (NaN = unknown)")
        occ.setflags(write=False)
        object.__setattr__(self, "occupancy", occ)
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))
        object.__setattr__(self, "resolution", float(self.resolution))

    # -- derived masks -------------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, int]:
        """``(H, W)`` = (rows along y, columns along x)."""
        return self.occupancy.shape

    @cached_property
    def occupied(self) -> np.ndarray:
        """``(H, W)`` bool, C-contiguous: cells that reflect beams."""
        with np.errstate(invalid="ignore"):
            return np.ascontiguousarray(self.occupancy > self.occupied_thresh)

    @cached_property
    def free(self) -> np.ndarray:
        """``(H, W)`` bool: known free cells."""
        with np.errstate(invalid="ignore"):
            return self.occupancy < self.free_thresh

    @cached_property
    def distance(self) -> np.ndarray:
        """``(H, W)`` distance (m) from each cell centre to the nearest occupied cell centre
        (a large value if the map has no occupied cell)."""
        if not self.occupied.any():
            return np.full(self.shape, np.inf)
        return edt_metres(~self.occupied, self.resolution)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the grid's extent, metres."""
        ox, oy = self.origin
        H, W = self.shape
        return ox, oy, ox + W * self.resolution, oy + H * self.resolution

    # -- coordinates ---------------------------------------------------------------------------
    def cell_of(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Column and row indices ``(i, j)`` of ``(N, 2)`` world points (may lie outside the grid)."""
        p = np.asarray(xy, dtype=float).reshape(-1, 2)
        i = np.floor((p[:, 0] - self.origin[0]) / self.resolution).astype(np.int64)
        j = np.floor((p[:, 1] - self.origin[1]) / self.resolution).astype(np.int64)
        return i, j

    def cell_centres(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """World ``(N, 2)`` centres of cells ``(i, j)``."""
        return np.column_stack((self.origin[0] + (np.asarray(i) + 0.5) * self.resolution,
                                self.origin[1] + (np.asarray(j) + 0.5) * self.resolution))

    # -- the Map protocol ----------------------------------------------------------------------
    def raycast(self, poses: Pose | np.ndarray, laser: LaserSpec) -> np.ndarray:
        """Virtual sensor (VSD): one pose → ``(n_beams,)``, ``(N, 3)`` poses → ``(N, n_beams)``.

        Metres; ``inf`` where no occupied cell is met before ``laser.max_range``. The range to a
        hit cell is the midpoint of the beam's chord through it, so it is within half a cell
        (along the beam) of a surface that crosses the cell."""
        arr, single = as_pose_array(poses)
        r = raycast_grid(np.ascontiguousarray(arr), np.asarray(laser.angles, dtype=float),
                         self.occupied, self.origin[0], self.origin[1], self.resolution,
                         float(laser.max_range))
        return r[0] if single else r

    def in_bounds(self, xy: np.ndarray) -> np.ndarray:
        """Which ``(N, 2)`` points lie inside the grid's extent (whose :meth:`cell_of` is a cell of
        the grid), in one compiled pass: a tracker asks it of one pose every scan."""
        p = np.ascontiguousarray(np.asarray(xy, dtype=float).reshape(-1, 2))
        H, W = self.shape
        return inside_kernel(p, self.origin[0], self.origin[1], self.resolution, W, H)

    def is_free(self, xy: np.ndarray, clearance: float = 0.0) -> np.ndarray:
        """Which ``(N, 2)`` points lie in known free cells whose centre is at least
        ``clearance`` + half a cell (m) from the centre of any occupied cell."""
        i, j = self.cell_of(xy)
        ok = self.in_bounds(xy)
        out = np.zeros(ok.shape, dtype=bool)
        ii, jj = i[ok], j[ok]
        out[ok] = self.free[jj, ii] & (self.distance[jj, ii] >= clearance + 0.5 * self.resolution)
        return out

    @cached_property
    def _normal_field(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Structure tensor ``(Jxx, Jxy, Jyy)`` of the Gaussian-smoothed occupied mask."""
        f = ndimage.gaussian_filter(self.occupied.astype(float), sigma=1.0)
        gy, gx = np.gradient(f)
        sm = lambda a: ndimage.gaussian_filter(a, sigma=1.5)  # noqa: E731
        return sm(gx * gx), sm(gx * gy), sm(gy * gy)

    def sample_points(self, spacing: float) -> tuple[np.ndarray, np.ndarray]:
        """Occupied cells as points about every ``spacing`` metres, with unit in-plane normals.

        Points are the mean of the occupied cell centres in each ``spacing`` square; a normal is
        the dominant gradient direction of the smoothed occupancy there (the principal axis of
        its structure tensor), turned to face the side with more free space. Both ``(M, 2)``."""
        jj, ii = np.nonzero(self.occupied)
        if ii.size == 0:
            return np.empty((0, 2)), np.empty((0, 2))
        centres = self.cell_centres(ii, jj)
        step = max(float(spacing), self.resolution)
        key = np.floor((centres - np.array(self.origin)) / step).astype(np.int64)
        _, inv, cnt = np.unique(key[:, 0] * (1 << 32) + key[:, 1], return_inverse=True,
                                return_counts=True)
        pts = np.column_stack([np.bincount(inv, centres[:, k]) / cnt for k in (0, 1)])
        jxx, jxy, jyy = (np.bincount(inv, a[jj, ii]) / cnt for a in self._normal_field)
        phi = 0.5 * np.arctan2(2.0 * jxy, jxx - jyy)
        normals = np.column_stack((np.cos(phi), np.sin(phi)))
        # orient towards free space: compare the free mask a few cells along ±n
        probe = 2.0 * self.resolution

        def free_at(p: np.ndarray) -> np.ndarray:
            return self.is_free(p).astype(float)

        flip = free_at(pts - probe * normals) > free_at(pts + probe * normals)
        normals[flip] *= -1.0
        return pts, normals
