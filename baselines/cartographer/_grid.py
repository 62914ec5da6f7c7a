"""The probability grid Cartographer's 2D scan matchers read, made from a tfloc map.

Cartographer matches against a submap's ``ProbabilityGrid`` (``submaps.grid_options_2d.resolution``
0.05 m). Here the grid is the map's: a :class:`~tfloc.maps.grid.GridMap` at 0.05 m is used cell
for cell, any other map is rasterised at 0.05 m (:func:`_occupied`). A cell
the map calls occupied reads ``occupied_probability`` (0.9, ``kMaxProbability``: where a submap's
wall cells saturate after repeated hits), every other cell, and every cell off the grid,
``kMinProbability`` 0.1, which is what Cartographer reads for an unknown cell too
(``kMaxCorrespondenceCost``). The Ceres matcher reads the *correspondence cost* 1 − P.

:func:`bicubic` is ``ceres::BiCubicInterpolator`` (``ceres/cubic_interpolation.h``: Catmull–Rom
Hermite splines along columns then rows) over the cost grid with Cartographer's padding
(``occupied_space_cost_function_2d.cc``: a cell outside the grid reads ``kMaxCorrespondenceCost``),
returning the value and its derivatives. Coordinates are cell-centred: cell ``[j, i]`` has its
centre at ``origin + (i + ½, j + ½) · resolution``. Metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from tfloc.maps.build import rasterize
from tfloc.maps.cache import cached
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap

#: Cartographer's probability clamp (``mapping/probability_values.h``)
MIN_PROBABILITY, MAX_PROBABILITY = 0.1, 0.9
#: ``TRAJECTORY_BUILDER_2D.submaps.grid_options_2d.resolution`` (metres)
RESOLUTION = 0.05


@dataclass(frozen=True, eq=False)
class ProbabilityGrid:
    """Occupancy probabilities ``prob`` ``(H, W)`` (row = y, column = x) of cells ``resolution``
    metres wide, cell ``[0, 0]``'s outer corner at ``origin``; ``cost`` = 1 − ``prob``."""

    prob: np.ndarray
    resolution: float
    origin: tuple[float, float]

    @cached_property
    def cost(self) -> np.ndarray:
        """``1 − prob``, computed once (the Ceres matcher reads it at every evaluation)."""
        return 1.0 - self.prob

    def cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Integer ``(column, row)`` of world points ``(..., 2)`` (may lie off the grid)."""
        i = np.floor((xy[..., 0] - self.origin[0]) / self.resolution).astype(np.int64)
        j = np.floor((xy[..., 1] - self.origin[1]) / self.resolution).astype(np.int64)
        return i, j

    def probability_at_cells(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """``GetProbability``: the cells' probabilities, ``kMinProbability`` off the grid."""
        H, W = self.prob.shape
        inside = (i >= 0) & (i < W) & (j >= 0) & (j < H)
        out = np.full(np.shape(i), MIN_PROBABILITY)
        out[inside] = self.prob[j[inside], i[inside]]
        return out


def _occupied(map_: object) -> tuple[np.ndarray, tuple[float, float]]:
    """The occupied cells of ``map_`` on a 0.05 m grid and the grid's origin: a grid at 0.05 m
    as it is, a vector map rasterised (:func:`tfloc.maps.build.rasterize`: every cell a wall
    passes through), any other map from its surface samples; the last two offset by half a cell,
    so that walls on round coordinates run through cell centres."""
    if isinstance(map_, GridMap) and abs(map_.resolution - RESOLUTION) < 1e-9:
        return map_.occupied, map_.origin
    if isinstance(map_, VectorMap):
        grid = rasterize(map_, RESOLUTION)
        return grid.occupied, grid.origin
    pts, _ = map_.sample_points(RESOLUTION / 2.0)
    pts = np.asarray(pts, dtype=float).reshape(-1, 2)
    if len(pts) == 0:
        return np.zeros((1, 1), dtype=bool), (0.0, 0.0)
    lo = (np.floor(pts.min(axis=0) / RESOLUTION) - 1.5) * RESOLUTION
    W, H = np.floor((pts.max(axis=0) - lo) / RESOLUTION).astype(int) + 2
    occ = np.zeros((H, W), dtype=bool)
    i = np.floor((pts[:, 0] - lo[0]) / RESOLUTION).astype(np.int64)
    j = np.floor((pts[:, 1] - lo[1]) / RESOLUTION).astype(np.int64)
    occ[j, i] = True
    return occ, (float(lo[0]), float(lo[1]))


def probability_grid(map_: object, occupied_probability: float) -> ProbabilityGrid:
    """The map's probability grid (module notes), built once per map and probability."""

    def build() -> ProbabilityGrid:
        occ, origin = _occupied(map_)
        prob = np.where(occ, occupied_probability, MIN_PROBABILITY).astype(np.float64)
        prob.setflags(write=False)
        return ProbabilityGrid(prob, RESOLUTION, origin)

    return cached(map_, ("cartographer-grid", round(occupied_probability, 9)), build)


def _hermite(p0, p1, p2, p3, x):  # noqa: ANN001, ANN202 - arrays of one shape
    """``ceres::CubicHermiteSpline``: value and derivative at ``x`` ∈ [0, 1] between p1 and p2."""
    a = 0.5 * (-p0 + 3.0 * p1 - 3.0 * p2 + p3)
    b = 0.5 * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3)
    c = 0.5 * (-p0 + p2)
    return p1 + x * (c + x * (b + x * a)), c + x * (2.0 * b + 3.0 * a * x)


def bicubic(values: np.ndarray, row: np.ndarray, col: np.ndarray, outside: float
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``BiCubicInterpolator::Evaluate`` of ``values`` ``(H, W)`` at fractional ``(row, col)``
    (``(N,)`` each; cells off the grid read ``outside``): value, d/drow, d/dcol."""
    H, W = values.shape
    r0 = np.floor(row).astype(np.int64)
    c0 = np.floor(col).astype(np.int64)
    fr, fc = row - r0, col - c0
    rows = r0[:, None] + np.arange(-1, 3)[None, :]  # (N, 4)
    cols = c0[:, None] + np.arange(-1, 3)[None, :]
    rr, cc = rows[:, :, None], cols[:, None, :]  # (N, 4, 4): [point, row k, column l]
    inside = (rr >= 0) & (rr < H) & (cc >= 0) & (cc < W)
    patch = np.where(inside, values[np.clip(rr, 0, H - 1), np.clip(cc, 0, W - 1)], outside)
    x = fc[:, None]
    f, dfdc = _hermite(patch[:, :, 0], patch[:, :, 1], patch[:, :, 2], patch[:, :, 3], x)  # (N, 4) per row
    y = fr
    value, dfdr = _hermite(f[:, 0], f[:, 1], f[:, 2], f[:, 3], y)
    dcol, _ = _hermite(dfdc[:, 0], dfdc[:, 1], dfdc[:, 2], dfdc[:, 3], y)
    return value, dfdr, dcol


def cost_at(grid: ProbabilityGrid, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Interpolated correspondence cost at world points ``(N, 2)`` and its gradient in x and y
    (per metre): Cartographer's occupied-space residual before its weight."""
    col = (xy[:, 0] - grid.origin[0]) / grid.resolution - 0.5
    row = (xy[:, 1] - grid.origin[1]) / grid.resolution - 0.5
    value, drow, dcol = bicubic(grid.cost, row, col, 1.0 - MIN_PROBABILITY)
    return value, dcol / grid.resolution, drow / grid.resolution
