"""Cartographer's 2D submaps as local SLAM builds them: ``Submap2D`` over a ``ProbabilityGrid``,
the ``ProbabilityGridRangeDataInserter2D`` and ``ActiveSubmaps2D``
(``mapping/2d/submap_2d.cc``, ``mapping/2d/probability_grid_range_data_inserter_2d.cc``).

* **Insertion**: every hit cell takes the hit update once, then every cell a ray crosses (from the
  origin to a return, its end cell excluded; to a miss, its end cell included) the miss update
  (``insert_free_space``), a cell touched once per insertion (Cartographer's update marker: a hit
  wins over a miss in the same scan). An update multiplies the cell's odds by
  odds(``hit_probability``) or odds(``miss_probability``), clamped to [0.1, 0.9]; an unknown cell
  takes the update's own probability. Kept as float64 probabilities (Cartographer stores 16-bit
  values through lookup tables: differences below 1e-4). Rays are traversed cell by cell (an
  exact grid traversal, where Cartographer steps at 1/1000 of a cell: the same cells but where
  a ray grazes a cell corner).
* **Growth**: the grid grows to hold every point (by whole metres of margin; Cartographer doubles).
* **ActiveSubmaps2D**: a new submap (origin at the scan's origin) when the newest holds
  ``num_range_data`` scans; at most two active, the older dropped from the active pair when
  a new one starts and *finished* when it holds ``2·num_range_data``; scans are matched against
  the older (``front``).

Grid cells: ``prob[j, i]`` covers x ∈ origin_x + [i, i+1)·resolution, y likewise (metres); unknown NaN.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._grid import MIN_PROBABILITY, ProbabilityGrid

_MARGIN_M = 2.0  # growth margin beyond the points (metres)


def _odds(p: float) -> float:
    return p / (1.0 - p)


@njit(cache=True, nogil=True)
def _update(prob: np.ndarray, touched: np.ndarray, j: int, i: int, odds: float, p_update: float) -> None:
    if touched[j, i]:
        return
    touched[j, i] = True
    p = prob[j, i]
    if np.isnan(p):
        prob[j, i] = p_update
        return
    o = odds * p / (1.0 - p)
    prob[j, i] = min(max(o / (1.0 + o), 0.1), 0.9)


@njit(cache=True, nogil=True)
def _insert(prob: np.ndarray, touched: np.ndarray, ox: float, oy: float, ends: np.ndarray, n_hits: int,
            hit_odds: float, hit_p: float, miss_odds: float, miss_p: float, free_space: bool) -> None:
    """Insert rays from ``(ox, oy)`` to ``ends`` ``(K, 2)`` (grid units, cells; the first
    ``n_hits`` are returns, the rest misses)."""
    for k in range(n_hits):
        _update(prob, touched, int(math.floor(ends[k, 1])), int(math.floor(ends[k, 0])), hit_odds, hit_p)
    if not free_space:
        return
    for k in range(ends.shape[0]):
        ex, ey = ends[k, 0], ends[k, 1]
        i, j = int(math.floor(ox)), int(math.floor(oy))
        ei, ej = int(math.floor(ex)), int(math.floor(ey))
        dx, dy = ex - ox, ey - oy
        si = 1 if dx > 0 else -1
        sj = 1 if dy > 0 else -1
        tdx = abs(1.0 / dx) if dx != 0 else np.inf
        tdy = abs(1.0 / dy) if dy != 0 else np.inf
        tx = ((i + 1 - ox) if dx > 0 else (ox - i)) * tdx if dx != 0 else np.inf
        ty = ((j + 1 - oy) if dy > 0 else (oy - j)) * tdy if dy != 0 else np.inf
        n = abs(ei - i) + abs(ej - j)
        for _ in range(n):
            _update(prob, touched, j, i, miss_odds, miss_p)
            if tx < ty:
                tx += tdx
                i += si
            else:
                ty += tdy
                j += sj
        if k >= n_hits:  # a miss: its end cell is free too
            _update(prob, touched, ej, ei, miss_odds, miss_p)


class Submap:
    """One submap: its origin (the local-frame position of its first scan, metres), its grid and
    the number of scans inserted."""

    def __init__(self, origin_xy: tuple[float, float], resolution: float) -> None:
        self.origin_xy = (float(origin_xy[0]), float(origin_xy[1]))
        self.resolution = resolution
        self.corner = np.array(self.origin_xy) - _MARGIN_M
        n = int(round(2 * _MARGIN_M / resolution))
        self.prob = np.full((n, n), np.nan)
        self.num_range_data = 0
        self.finished = False

    def _grow(self, pts: np.ndarray) -> None:
        """Enlarge the grid (keeping its cells) until it holds ``pts`` ``(K, 2)`` (metres)."""
        r = self.resolution
        size = r * np.array(self.prob.shape[::-1])
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        if np.all(lo >= self.corner) and np.all(hi < self.corner + size):
            return
        add_lo = np.where(lo < self.corner, np.ceil((self.corner - lo + _MARGIN_M) / r), 0).astype(int)
        add_hi = np.where(hi >= self.corner + size, np.ceil((hi - self.corner - size + _MARGIN_M) / r), 0
                          ).astype(int)
        H, W = self.prob.shape
        grown = np.full((H + add_lo[1] + add_hi[1], W + add_lo[0] + add_hi[0]), np.nan)
        grown[add_lo[1]:add_lo[1] + H, add_lo[0]:add_lo[0] + W] = self.prob
        self.prob, self.corner = grown, self.corner - r * add_lo

    def insert(self, origin: np.ndarray, returns: np.ndarray, misses: np.ndarray, hit_probability: float,
               miss_probability: float, insert_free_space: bool) -> None:
        """Insert one scan: ``origin`` ``(2,)`` and world (submap-frame) ``returns`` / ``misses``
        ``(K, 2)``, metres."""
        ends = np.concatenate((returns.reshape(-1, 2), misses.reshape(-1, 2)))
        self._grow(np.vstack((ends, origin[None, :])))
        g = (ends - self.corner) / self.resolution
        o = (origin - self.corner) / self.resolution
        touched = np.zeros(self.prob.shape, dtype=np.bool_)
        _insert(self.prob, touched, float(o[0]), float(o[1]), np.ascontiguousarray(g), len(returns),
                _odds(hit_probability), hit_probability, _odds(miss_probability), miss_probability,
                bool(insert_free_space))
        self.num_range_data += 1

    def grid(self) -> ProbabilityGrid:
        """The submap as the scan matchers read it (unknown: ``kMinProbability``)."""
        p = np.where(np.isnan(self.prob), MIN_PROBABILITY, self.prob)
        return ProbabilityGrid(p, self.resolution, (float(self.corner[0]), float(self.corner[1])))


class ActiveSubmaps:
    """``ActiveSubmaps2D``: the (at most two) submaps scans are inserted into (module notes)."""

    def __init__(self, num_range_data: int, resolution: float) -> None:
        self.num_range_data = num_range_data
        self.resolution = resolution
        self.submaps: list[Submap] = []

    def insert(self, origin: np.ndarray, returns: np.ndarray, misses: np.ndarray, hit_probability: float,
               miss_probability: float, insert_free_space: bool) -> tuple[list[Submap], bool]:
        """Insert a scan (local frame); the submaps it went into (older first) and whether the
        older one was finished by it."""
        if not self.submaps or self.submaps[-1].num_range_data == self.num_range_data:
            if len(self.submaps) >= 2:
                self.submaps.pop(0)
            self.submaps.append(Submap((origin[0], origin[1]), self.resolution))
        for s in self.submaps:
            s.insert(origin, returns, misses, hit_probability, miss_probability, insert_free_space)
        finished = self.submaps[0].num_range_data == 2 * self.num_range_data
        if finished:
            self.submaps[0].finished = True
        return list(self.submaps), finished

