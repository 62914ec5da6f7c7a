"""tfloc: 2D laser localization by turning-function scan matching, and a benchmark harness.

This module is the public face only; the layers below it are described in docs/DESIGN.md.

Public API::

    import tfloc
    m = tfloc.load_map("data/maps/office-2.geojson")
    est = tfloc.localize(m, tfloc.LaserSpec.lms200(), ranges, tfloc.Pose(1.0, 2.0, 0.1), matcher="tf")
"""
# ruff: noqa: E402  (numba's cache is pointed at this version's directory before any import)

from __future__ import annotations

from . import _kernel_cache

_kernel_cache.configure()  # before any module with a compiled kernel is imported

from typing import Any

import numpy as np

from .core.laser import LaserSpec
from .core.matcher import Matcher, available_matchers, get_matcher
from .core.pose import Pose, angdiff
from .core.problem import Estimate, Problem
from .errors import InvalidProblemError, MapFormatError, MatcherError, TflocError
from .io.maps import load_map
from .maps import GridMap, Map, VectorMap

__version__ = "0.1.0"

__all__ = [
    "Estimate", "GridMap", "InvalidProblemError", "LaserSpec", "Map", "MapFormatError", "Matcher",
    "MatcherError", "Pose", "Problem", "TflocError", "VectorMap", "angdiff",
    "available_matchers", "get_matcher", "load_map", "localize",
]


def localize(map: Map, laser: LaserSpec, ranges: np.ndarray, initial: Pose,
             matcher: str | Matcher = "tf", **params: Any) -> Estimate:
    """Localize one scan: ranges (metres) taken by ``laser`` near ``initial`` in ``map``."""
    m = get_matcher(matcher, **params) if isinstance(matcher, str) else matcher
    return m.localize(Problem(map, laser, np.asarray(ranges, dtype=float), initial))
