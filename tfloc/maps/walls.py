"""Walls drawn several cells thick in an occupancy grid: where their surfaces are.

A grid map built from real scans (hit counting with free-space carving as in ``tfloc
real-data``; GMapping, Cartographer and slam_toolbox alike) draws a wall as a band of occupied
cells: the scans' registration error and range noise spread the returns from one surface over
two or more cells across it. Measured across the occupied cells of the Intel and MIT CSAIL grids
(``tfloc real-data``, ``results/tf-plus-real-diagnostics.md``), a band is about 2 cells (10 and
8 cm) thick at the median; a map built from scans with larger registration error draws thicker
bands. A band carries no information about where inside it a return lies; its *surfaces* (where
free space ends) do. ``tf-plus`` measures a return from the surface on its sensor's side and
estimates how deep behind it the scan's returns lie (:mod:`tfloc.tfplus.refine`).

:func:`run_extents` gives, for every occupied cell's point, how far the run of occupied cells
through it extends along its normal either way (walking the occupancy in steps of a third of a
cell, which never land on a cell border when they start at a cell centre on an axis), capped at
``max_thickness`` (a run that long is a solid object, a pillar or a cabinet drawn filled).
"""

from __future__ import annotations

import numpy as np


def run_extents(points: np.ndarray, normals: np.ndarray, occupied: np.ndarray, origin: np.ndarray,
                resolution: float, max_thickness: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """How far (metres) the run of ``occupied`` cells ``(ny, nx)`` (cell ``(0, 0)``'s corner at
    ``origin``, ``resolution`` metres) through each of ``points`` ``(M, 2)`` extends along
    ``+normals`` and along ``−normals`` ``(M, 2)`` (unit), each capped at ``max_thickness``; 0 for
    a point in no occupied cell. The surface on either side lies a sixth of a cell beyond (the
    walk's step, halved)."""
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
            t[alive] = np.minimum(k * step, max_thickness)
        reach.append(t)
    return reach[0], reach[1]
