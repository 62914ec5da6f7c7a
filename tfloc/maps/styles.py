"""Map styles: the same corrected scans drawn as other mapping tools draw them.

A user's map comes from their own SLAM system, not from tfloc's counting model
(:func:`~tfloc.maps.build.grid_from_counts`, the "as-built" style). Each function here turns the
per-cell beam counts of the corrected scans (:class:`~tfloc.maps.build.ScanCounts`), or the
as-built grid, into one other style, on the same cell frame, so that every style of a log shares
the scans, the truth and the initial poses. What each style stands for and why:
docs/robustness.md.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from .build import COUNT_OCCUPIED_THRESH, ScanCounts
from .grid import GridMap

#: map_saver's YAML thresholds (``occupied_thresh`` 0.65, ``free_thresh`` 0.196), written by ROS's
#: map_saver and by cartographer_ros's pbstream_to_ros_map alike.
SAVER_OCCUPIED_THRESH = 0.65
SAVER_FREE_THRESH = 0.196
#: Cartographer's 2D range-data inserter defaults: the probability a hit and a miss stand for, and
#: its probability clamp (``kMinProbability``, ``kMaxProbability``).
CARTO_HIT, CARTO_MISS = 0.55, 0.49
CARTO_MIN_P, CARTO_MAX_P = 0.1, 0.9


def _logit(p: float) -> float:
    return float(np.log(p / (1.0 - p)))


def hits_only(counts: ScanCounts, min_hits: int = 2, name: str = "hits-only") -> GridMap:
    """Occupied where at least ``min_hits`` returns ended in a cell, no free-space carving.

    Written as a binary image (black hits, white elsewhere), as a rasteriser of a point cloud
    writes it: with no carving there is no evidence of unknown space, and marking every other
    cell unknown would leave no free space at all. Occupancy 1 / 0, map_saver's thresholds."""
    occ = np.where(counts.hits >= min_hits, 1.0, 0.0).astype(np.float32)
    return GridMap(occ, counts.resolution, counts.origin, SAVER_OCCUPIED_THRESH, SAVER_FREE_THRESH, name)


def thickened(grid: GridMap, cells: int, name: str | None = None) -> GridMap:
    """``grid`` with every occupied region grown by ``cells`` cells (a square of side 2·cells + 1:
    every cell within Chebyshev distance ``cells`` of an occupied cell becomes occupied, 1.0)."""
    if cells < 0:
        raise ValueError(f"thickening must be ≥ 0 cells, got {cells}")
    grown = ndimage.binary_dilation(grid.occupied, structure=np.ones((2 * cells + 1,) * 2, dtype=bool))
    occ = np.where(grown & ~grid.occupied, 1.0, grid.occupancy).astype(np.float32)
    return GridMap(occ, grid.resolution, grid.origin, grid.occupied_thresh, grid.free_thresh,
                   name or f"{grid.name}-thick-{cells}")


def incomplete(grid: GridMap, counts: ScanCounts, share: float = 0.10, name: str | None = None) -> GridMap:
    """``grid`` without the ``share`` least-observed of its occupied cells (they become unknown).

    Observations of a cell = hits + passes; ties go to fewer hits, then to the lower row-major
    index, so the choice is deterministic. ``round(share · occupied cells)`` cells are removed."""
    jj, ii = np.nonzero(grid.occupied)
    seen = (counts.hits + counts.passes)[jj, ii]
    order = np.lexsort((jj * grid.shape[1] + ii, counts.hits[jj, ii], seen))
    drop = order[: int(round(share * len(order)))]
    occ = np.array(grid.occupancy, dtype=np.float32)
    occ[jj[drop], ii[drop]] = np.nan
    return GridMap(occ, grid.resolution, grid.origin, grid.occupied_thresh, grid.free_thresh,
                   name or f"{grid.name}-incomplete")


def gmapping(counts: ScanCounts, name: str = "gmapping") -> GridMap:
    """GMapping's published map: a reached cell is 100 if more than ``occ_thresh`` = 25 % of the
    beams reaching it ended there, else 0 (gmapping has no grey); unreached cells unknown.
    Occupancy 1 / 0 / NaN with map_saver's thresholds (map_saver writes it as 0 / 254 / 205)."""
    total = counts.hits + counts.passes
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(total > 0, counts.hits / total, np.nan)
    occ = np.where(np.isnan(ratio), np.nan, np.where(ratio > COUNT_OCCUPIED_THRESH, 1.0, 0.0))
    return GridMap(occ.astype(np.float32), counts.resolution, counts.origin, SAVER_OCCUPIED_THRESH,
                   SAVER_FREE_THRESH, name)


def cartographer(counts: ScanCounts, name: str = "cartographer") -> GridMap:
    """A Cartographer-style probability grid: the odds of every hit (0.55) and miss (0.49)
    multiplied, the probability clamped to [0.1, 0.9]; unreached cells unknown. (Cartographer
    clamps after every update and counts a cell once per scan; this product of all counts is
    its order-free approximation.) Grey values stay: the grid keeps map_saver's thresholds, so
    walls seen only a few times fall between them, as they do when such a map is served."""
    total = counts.hits + counts.passes
    logodds = counts.hits * _logit(CARTO_HIT) + counts.passes * _logit(CARTO_MISS)
    p = np.clip(1.0 / (1.0 + np.exp(-logodds)), CARTO_MIN_P, CARTO_MAX_P)
    occ = np.where(total > 0, p, np.nan).astype(np.float32)
    return GridMap(occ, counts.resolution, counts.origin, SAVER_OCCUPIED_THRESH, SAVER_FREE_THRESH, name)
