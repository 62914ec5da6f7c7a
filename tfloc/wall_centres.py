"""Thick walls of an occupancy grid → their centre lines (what ``tf-plus`` fits real scans to).

A grid map built from real scans (hit counting, GMapping, Cartographer, slam_toolbox) draws a wall
as a band of occupied cells: the scans' registration error and range noise spread the returns
from one surface over two or more cells across it. Measured on the Intel and CSAIL grids: the
band is 2 cells (10 cm) thick at the median across the wall, 3–4 cells for a quarter of the
cells. Every cell of the band holds returns, so the surface the band stands for lies in its
middle. Fitting a scan to the band's *cells* leaves the scan free to slide across the band (any
position inside it costs nothing), and fitting it to the band's *first cell along a ray* (a
virtual scan) pulls the scan short by half the band. Fitting it to the band's centre line does
neither.

:func:`wall_centres` moves every occupied cell's centre along its normal to the middle of the
occupied run through it (walking the occupancy in steps of a third of a cell both ways, which
never land on a cell border when they start at a cell centre on an axis), as long as the run
is at most ``max_thickness`` thick; a thicker run is a solid object (a pillar, a cabinet drawn
filled), whose cells stay where they are. A wall seen from both sides whose two bands have
merged is centred in the middle of the physical wall, which is then half its thickness off for
each side (a limit, see ``docs/tf-plus.md``).
"""

from __future__ import annotations

import numpy as np


def run_extents(points: np.ndarray, normals: np.ndarray, occupied: np.ndarray, origin: np.ndarray,
                resolution: float, max_thickness: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """How far (metres) the run of ``occupied`` cells through each point extends along ``+normal``
    and along ``−normal`` (see :func:`wall_centres`), each capped at ``max_thickness``."""
    pts = np.asarray(points, dtype=float)
    nrm = np.asarray(normals, dtype=float)
    ny, nx = occupied.shape
    step = resolution / 3.0
    steps = int(np.ceil(max_thickness / step)) + 1

    def occ_at(p: np.ndarray) -> np.ndarray:
        ij = np.floor((p - origin) / resolution).astype(np.int64)
        ok = (ij[:, 0] >= 0) & (ij[:, 0] < nx) & (ij[:, 1] >= 0) & (ij[:, 1] < ny)
        out = np.zeros(len(p), dtype=bool)
        out[ok] = occupied[ij[ok, 1], ij[ok, 0]]
        return out

    reach = []
    for sign in (1.0, -1.0):
        t = np.zeros(len(pts))
        alive = occ_at(pts)
        for k in range(1, steps + 1):
            alive &= occ_at(pts + sign * (k * step) * nrm)
            t[alive] = k * step
        reach.append(t)
    return reach[0], reach[1]


def wall_centres(points: np.ndarray, normals: np.ndarray, occupied: np.ndarray, origin: np.ndarray,
                 resolution: float, max_thickness: float = 0.3) -> np.ndarray:
    """Each of ``points`` ``(M, 2)`` (metres) moved along its unit normal ``normals`` ``(M, 2)`` to
    the middle of the run of ``occupied`` cells ``(ny, nx)`` (cell ``(0, 0)``'s corner at
    ``origin``, ``resolution`` metres) it lies in; points whose run is thicker than
    ``max_thickness`` metres, or that lie in no occupied cell, stay. Returns ``(M, 2)``."""
    pts = np.asarray(points, dtype=float)
    nrm = np.asarray(normals, dtype=float)
    ny, nx = occupied.shape
    step = resolution / 3.0
    steps = int(np.ceil(max_thickness / step)) + 1

    def occ_at(p: np.ndarray) -> np.ndarray:
        ij = np.floor((p - origin) / resolution).astype(np.int64)
        ok = (ij[:, 0] >= 0) & (ij[:, 0] < nx) & (ij[:, 1] >= 0) & (ij[:, 1] < ny)
        out = np.zeros(len(p), dtype=bool)
        out[ok] = occupied[ij[ok, 1], ij[ok, 0]]
        return out

    reach = []
    for sign in (1.0, -1.0):
        t = np.zeros(len(pts))
        alive = occ_at(pts)
        for k in range(1, steps + 1):
            alive &= occ_at(pts + sign * (k * step) * nrm)
            t[alive] = k * step
        reach.append(t)
    plus, minus = reach
    thick = plus + minus + step
    shift = np.where((thick <= max_thickness + 1e-9) & occ_at(pts), 0.5 * (plus - minus), 0.0)
    return pts + shift[:, None] * nrm
