"""Where a map knows the world: inside its mapped area and, on an occupancy grid, not in an
unknown cell. The one rule behind "the pose lies outside the map" (a dataset's start,
:func:`tfloc.io.scenario.check_usable`; a trajectory's stretches,
:func:`tfloc.evaluation.recording.coverage_flags`)."""

from __future__ import annotations

import numpy as np

from tfloc.core.map import Map


def in_known_area(map_: Map, xy: np.ndarray) -> np.ndarray:
    """Which ``(N, 2)`` points (metres) lie where the map knows the world: ``map_.in_bounds``
    and, for a map with an ``occupancy`` raster (a :class:`~tfloc.maps.grid.GridMap`), in a cell
    that is not unknown (NaN)."""
    p = np.asarray(xy, dtype=float).reshape(-1, 2)
    ok = np.isfinite(p).all(axis=1)
    if ok.any():
        ok[ok] = np.asarray(map_.in_bounds(p[ok]), dtype=bool)
    occ = getattr(map_, "occupancy", None)
    if occ is not None and ok.any() and hasattr(map_, "cell_of"):
        i, j = map_.cell_of(p[ok])
        ok[np.flatnonzero(ok)] = ~np.isnan(occ[j, i])
    return ok
