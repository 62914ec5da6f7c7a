"""Building a :class:`GridMap`: from scans at known poses (hit counting with free-space carving),
or by rasterising a :class:`VectorMap`."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tfloc.core.laser import LaserSpec

from ._gridcast import carve_grid
from .grid import GridMap
from .vector import VectorMap

#: GMapping's default ``occ_thresh``: a cell is occupied if more than 25 % of the beams that
#: reached it ended in it.
COUNT_OCCUPIED_THRESH = 0.25
#: and free if fewer than 10 % did (and at least one beam crossed it).
COUNT_FREE_THRESH = 0.10


def _frame(points: np.ndarray, resolution: float, margin: float) -> tuple[tuple[float, float], int, int]:
    lo = np.floor((points.min(axis=0) - margin) / resolution) * resolution
    hi = points.max(axis=0) + margin
    W, H = (int(math.ceil((hi[k] - lo[k]) / resolution)) for k in (0, 1))
    return (float(lo[0]), float(lo[1])), W, H


@dataclass(frozen=True, eq=False)
class ScanCounts:
    """Per-cell beam counts of scans at known poses, on one grid frame.

    Attributes:
        hits: ``(H, W)`` returns that ended in each cell (float, whole numbers).
        passes: ``(H, W)`` beams that crossed each cell before their return (0 without carving).
        origin: ``(ox, oy)`` metres, outer corner of cell ``[0, 0]`` (row 0 = lowest y).
        resolution: metres per cell.
    """

    hits: np.ndarray
    passes: np.ndarray
    origin: tuple[float, float]
    resolution: float


def scan_counts(ranges: np.ndarray, poses: np.ndarray, laser: LaserSpec, resolution: float = 0.05,
                margin: float = 1.0, carve: bool = True) -> ScanCounts:
    """Hit and pass counts of scans ``(N, n_beams)`` taken at world laser poses ``(N, 3)`` (m, rad).

    Every return adds a hit to its cell; with ``carve``, every cell a beam crosses before its
    return adds a pass (beams without a return carve nothing). The extent covers every return
    and pose plus ``margin`` metres."""
    R = np.asarray(ranges, dtype=float).reshape(len(poses), -1)
    P = np.asarray(poses, dtype=float).reshape(-1, 3)
    ok = laser.valid(R)
    ang = P[:, 2:3] + laser.angles[None, :]
    ex = P[:, 0:1] + np.where(ok, R, 0.0) * np.cos(ang)
    ey = P[:, 1:2] + np.where(ok, R, 0.0) * np.sin(ang)
    ends = np.column_stack((ex[ok], ey[ok]))
    origin, W, H = _frame(np.vstack((ends, P[:, :2])), resolution, margin)
    ends_c = (ends - np.array(origin)) / resolution
    ij = np.floor(ends_c).astype(np.int64)
    hits = np.bincount(ij[:, 1] * W + ij[:, 0], minlength=W * H).reshape(H, W).astype(float)
    passes = np.zeros((H, W), dtype=np.int64)
    if carve:
        starts = np.repeat((P[:, :2] - np.array(origin)) / resolution, ok.sum(axis=1), axis=0)
        carve_grid(passes, np.ascontiguousarray(starts), np.ascontiguousarray(ends_c))
    return ScanCounts(hits, passes, origin, resolution)


def grid_from_counts(counts: ScanCounts, name: str = "scans") -> GridMap:
    """The counting model's grid: occupancy = hits / (hits + passes), NaN where no beam reached;
    thresholds :data:`COUNT_OCCUPIED_THRESH`, :data:`COUNT_FREE_THRESH`."""
    total = counts.hits + counts.passes
    with np.errstate(invalid="ignore", divide="ignore"):
        occ = np.where(total > 0, counts.hits / total, np.nan)
    return GridMap(occ, counts.resolution, counts.origin, COUNT_OCCUPIED_THRESH, COUNT_FREE_THRESH, name)


def grid_from_scans(ranges: np.ndarray, poses: np.ndarray, laser: LaserSpec, resolution: float = 0.05,
                    margin: float = 1.0, carve: bool = True, name: str = "scans") -> GridMap:
    """Occupancy grid from scans ``(N, n_beams)`` taken at world laser poses ``(N, 3)`` (m, rad):
    :func:`scan_counts` then :func:`grid_from_counts` (hit counting, with ``carve`` free-space
    carving; occupancy = hits / (hits + passes), NaN where no beam reached)."""
    return grid_from_counts(scan_counts(ranges, poses, laser, resolution, margin, carve), name)


def rasterize(vmap: VectorMap, resolution: float, margin: float = 0.5, name: str | None = None) -> GridMap:
    """A grid of a vector map: every cell a wall or obstacle edge passes through is occupied (1,
    exact grid traversal, so no beam can slip through a diagonal wall), cells whose centre is in
    the map's free space are free (0), the rest unknown (NaN). The grid is offset by half a cell
    so that walls on round coordinates run through cell centres."""
    segs = vmap.segments
    pts = np.vstack((segs[:, :2], segs[:, 2:]))
    (ox, oy), W, H = _frame(pts, resolution, margin)
    origin = (ox - 0.5 * resolution, oy - 0.5 * resolution)
    W, H = W + 1, H + 1
    a = (segs[:, :2] - np.array(origin)) / resolution
    b = (segs[:, 2:] - np.array(origin)) / resolution
    crossed = np.zeros((H, W), dtype=np.int64)
    carve_grid(crossed, np.ascontiguousarray(a), np.ascontiguousarray(b))
    ends = np.floor(np.vstack((a, b))).astype(np.int64)
    crossed[ends[:, 1], ends[:, 0]] += 1
    occ = np.full((H, W), np.nan, dtype=np.float32)
    jj, ii = np.mgrid[0:H, 0:W]
    centres = np.column_stack((origin[0] + (ii.ravel() + 0.5) * resolution,
                               origin[1] + (jj.ravel() + 0.5) * resolution))
    occ.ravel()[vmap.is_free(centres)] = 0.0
    occ[crossed > 0] = 1.0
    return GridMap(occ, resolution, origin, name=name or f"{vmap.name}@{resolution:g}m")
