"""A map handed over as scans: virtual 360° scans from a lattice of free positions.

Scan matchers built for SLAM (OpenKarto's) correlate a scan with *other scans*, not with a map. A
tfloc map has no recorded scans, so the lattice stands in for them: positions every ``spacing``
metres (cell centres of a square grid over the map's bounds) that lie in free space at least
``clearance`` metres from any obstacle, each with the virtual sensor's 360° scan from there. The
positions are computed when the lattice is built; a position's scan is ray-cast the first time it
is asked for (a scan-to-scan map is used for one scan only, so most are never needed).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.maps.cache import cached


def ring_laser(max_range: float, resolution_deg: float) -> LaserSpec:
    """A 360° virtual laser: beams every ``resolution_deg`` from −180° (the last one short of +180°)."""
    res = math.radians(resolution_deg)
    n = int(round(360.0 / resolution_deg))
    return LaserSpec(float(max_range), (n - 1) * res, res, -math.pi)


class ScanLattice:
    """Free lattice positions of one map and their (lazily ray-cast) 360° virtual scans.

    Attributes:
        positions: ``(K, 2)`` metres, world frame; the scans look along +x (heading 0).
        laser: the virtual 360° laser.
    """

    def __init__(self, map_: Any, positions: np.ndarray, laser: LaserSpec) -> None:
        self._map = map_
        self.positions = positions
        self.laser = laser
        self._ranges: dict[int, np.ndarray] = {}

    def near(self, xy: np.ndarray, radius: float) -> np.ndarray:
        """Indices of the positions within ``radius`` metres of ``xy``; the nearest one if none is."""
        if len(self.positions) == 0:
            return np.zeros(0, dtype=int)
        d = np.hypot(self.positions[:, 0] - xy[0], self.positions[:, 1] - xy[1])
        idx = np.flatnonzero(d <= radius)
        return idx if idx.size else np.array([int(np.argmin(d))])

    def ranges(self, idx: np.ndarray) -> np.ndarray:
        """The virtual scans at positions ``idx``, ``(len(idx), n_beams)`` metres (inf = no return)."""
        todo = [int(i) for i in idx if int(i) not in self._ranges]
        if todo:
            poses = np.column_stack((self.positions[todo], np.zeros(len(todo))))
            cast = np.atleast_2d(self._map.raycast(poses, self.laser))
            for i, r in zip(todo, cast, strict=True):
                self._ranges[i] = r
        return np.array([self._ranges[int(i)] for i in idx]).reshape(len(idx), self.laser.n_beams)


def scan_lattice(map_: Any, spacing: float, clearance: float, max_range: float,
                 resolution_deg: float) -> ScanLattice:
    """The cached :class:`ScanLattice` of ``map_`` (metres, degrees)."""

    def build() -> ScanLattice:
        x0, y0, x1, y1 = map_.bounds
        xs = np.arange(x0 + spacing / 2.0, x1, spacing)
        ys = np.arange(y0 + spacing / 2.0, y1, spacing)
        gx, gy = np.meshgrid(xs, ys)
        xy = np.column_stack((gx.ravel(), gy.ravel()))
        free = np.asarray(map_.is_free(xy, clearance), dtype=bool) if len(xy) else np.zeros(0, dtype=bool)
        return ScanLattice(map_, np.ascontiguousarray(xy[free]), ring_laser(max_range, resolution_deg))

    key = ("scan-lattice", round(spacing, 9), round(clearance, 9), round(max_range, 9), round(resolution_deg, 9))
    return cached(map_, key, build)
