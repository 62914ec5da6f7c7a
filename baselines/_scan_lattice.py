"""A map handed over as scans: virtual 360° scans from a lattice of free positions.

Scan matchers built for SLAM (OpenKarto's) correlate a scan with *other scans*, not with a map. A
tfloc map has no recorded scans, so the lattice stands in for them: positions every ``spacing``
metres (cell centres of a square grid over the map's bounds) that lie in free space at least
``clearance`` metres from any obstacle, each with a 360° scan of the map from there. The
positions are computed when the lattice is built; a position's scan is made the first time it
is asked for (a scan-to-scan map is used for one scan only, so most are never needed).

A scan's beam ends on the map's surface: ``surface = "near-face"`` is the virtual sensor's range
(the first occupied cell); ``"run-centre"`` is, on a grid, the middle of the run of occupied
cells the beam enters there (the map's own points: an occupied run in a grid built from scans is
the scatter of the returns around one surface, whose middle is where the recorded scans that a
SLAM system would hand Karto put it). On a vector map both are the ray-cast range.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

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

    def __init__(self, map_: Any, positions: np.ndarray, laser: LaserSpec, surface: str = "near-face") -> None:
        self._map = map_
        self.positions = positions
        self.laser = laser
        self.surface = surface
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
            if self.surface == "run-centre" and hasattr(self._map, "occupied"):
                cast = run_centre_ranges(self._map, poses, self.laser, cast)
            for i, r in zip(todo, cast, strict=True):
                self._ranges[i] = r
        return np.array([self._ranges[int(i)] for i in idx]).reshape(len(idx), self.laser.n_beams)


@njit(cache=True, nogil=True)
def _run_centres(px: np.ndarray, py: np.ndarray, cos: np.ndarray, sin: np.ndarray, near: np.ndarray,
                 offs: np.ndarray, occupied: np.ndarray, ox: float, oy: float, res: float) -> np.ndarray:
    """:func:`run_centre_ranges`'s loop: per pose ``p`` and beam ``b``, the samples
    ``near + offs[k]`` along the beam, the first occupied one and the run after it."""
    P, B = near.shape
    H, W = occupied.shape
    out = near.copy()
    for p in range(P):
        for b in range(B):
            r = near[p, b]
            if not np.isfinite(r):
                continue
            first, end = -1, offs.size
            for k in range(offs.size):
                t = r + offs[k]
                i = int(np.floor((px[p] + t * cos[p, b] - ox) / res))
                j = int(np.floor((py[p] + t * sin[p, b] - oy) / res))
                occ = 0 <= i < W and 0 <= j < H and occupied[j, i]
                if first < 0:
                    if occ:
                        first = k
                elif not occ:
                    end = k
                    break
            if first >= 0:
                out[p, b] = r + 0.5 * (offs[first] + offs[end - 1])
    return out


def run_centre_ranges(grid: Any, poses: np.ndarray, laser: LaserSpec, near: np.ndarray,
                      max_depth: float = 0.5) -> np.ndarray:
    """Ranges (metres) to the middle of the run of occupied cells each beam enters at its
    ray-cast range ``near`` ``(P, B)``: the beam is sampled every quarter cell from one cell
    before ``near`` to ``max_depth`` beyond it; the run is the contiguous occupied samples from
    the first one. Beams without a return keep ``inf``."""
    res = grid.resolution
    offs = np.arange(-res, max_depth + 0.125 * res, 0.25 * res)
    poses = np.asarray(poses, dtype=float).reshape(-1, 3)
    ang = poses[:, 2:3] + laser.angles[None, :]
    return _run_centres(np.ascontiguousarray(poses[:, 0]), np.ascontiguousarray(poses[:, 1]),
                        np.ascontiguousarray(np.cos(ang)), np.ascontiguousarray(np.sin(ang)),
                        np.ascontiguousarray(np.asarray(near, dtype=float).reshape(len(poses), -1)),
                        offs, np.ascontiguousarray(grid.occupied), float(grid.origin[0]),
                        float(grid.origin[1]), float(res))


def scan_lattice(map_: Any, spacing: float, clearance: float, max_range: float,
                 resolution_deg: float, surface: str = "near-face") -> ScanLattice:
    """The cached :class:`ScanLattice` of ``map_`` (metres, degrees; ``surface``: see the module)."""

    def build() -> ScanLattice:
        x0, y0, x1, y1 = map_.bounds
        xs = np.arange(x0 + spacing / 2.0, x1, spacing)
        ys = np.arange(y0 + spacing / 2.0, y1, spacing)
        gx, gy = np.meshgrid(xs, ys)
        xy = np.column_stack((gx.ravel(), gy.ravel()))
        free = np.asarray(map_.is_free(xy, clearance), dtype=bool) if len(xy) else np.zeros(0, dtype=bool)
        return ScanLattice(map_, np.ascontiguousarray(xy[free]), ring_laser(max_range, resolution_deg), surface)

    key = ("scan-lattice", round(spacing, 9), round(clearance, 9), round(max_range, 9), round(resolution_deg, 9),
           surface)
    return cached(map_, key, build)
