"""Load a map by its file type: GeoJSON → :class:`~tfloc.maps.vector.VectorMap`, ROS map YAML →
:class:`~tfloc.maps.grid.GridMap`."""

from __future__ import annotations

from pathlib import Path

from tfloc.core.map import Map
from tfloc.errors import MapFormatError


def load_map(path: str | Path) -> Map:
    """Load a map by its file type: ``.geojson``/``.json`` → VectorMap, ``.yaml`` → GridMap."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".geojson", ".json"):
        from .geojson import read_vector_map

        return read_vector_map(path)
    if suffix in (".yaml", ".yml"):
        from .rosmap import read_ros_map

        return read_ros_map(path)
    raise MapFormatError(f"{path}: unknown map type {suffix!r} (expected .geojson or .yaml)")
