"""tfloc: 2D laser localization by turning-function scan matching, and a benchmark harness.

Public API::

    import tfloc
    m = tfloc.load_map("data/maps/office-2.geojson")
    est = tfloc.localize(m, tfloc.LaserSpec.lms200(), ranges, tfloc.Pose(1.0, 2.0, 0.1), matcher="tf")
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .errors import InvalidProblemError, MapFormatError, MatcherError, TflocError
from .laser import LaserSpec
from .maps import GridMap, Map, VectorMap
from .matcher import Matcher, available_matchers, get_matcher
from .pose import Pose, angdiff
from .problem import Estimate, Problem

__version__ = "0.1.0"

__all__ = [
    "Estimate", "GridMap", "InvalidProblemError", "LaserSpec", "Map", "MapFormatError", "Matcher",
    "MatcherError", "Pose", "Problem", "TflocError", "VectorMap", "angdiff",
    "available_matchers", "get_matcher", "load_map", "localize",
]


def load_map(path: str | Path) -> Map:
    """Load a map by its file type: ``.geojson``/``.json`` → VectorMap, ``.yaml`` → GridMap."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".geojson", ".json"):
        from .io.geojson import read_vector_map

        return read_vector_map(path)
    if suffix in (".yaml", ".yml"):
        try:
            from .io.rosmap import read_ros_map
        except ImportError:
            raise MapFormatError(f"{path}: ROS map support is not available in this build") from None
        return read_ros_map(path)
    raise MapFormatError(f"{path}: unknown map type {suffix!r} (expected .geojson or .yaml)")


def localize(map: Map, laser: LaserSpec, ranges: np.ndarray, initial: Pose,
             matcher: str | Matcher = "tf", **params: Any) -> Estimate:
    """Localize one scan: ranges (metres) taken by ``laser`` near ``initial`` in ``map``."""
    m = get_matcher(matcher, **params) if isinstance(matcher, str) else matcher
    return m.localize(Problem(map, laser, np.asarray(ranges, dtype=float), initial))
