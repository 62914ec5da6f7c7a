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


def map_files(path: str | Path) -> list[Path]:
    """The files a map is made of: the file itself, and for a ROS map YAML also its image (if the
    YAML names one); files that do not exist are left out (loading the map reports them)."""
    path = Path(path)
    files = [path]
    if path.suffix.lower() in (".yaml", ".yml"):
        import yaml

        from .text import read_text

        try:
            doc = yaml.safe_load(read_text(path, MapFormatError, "map file"))
        except (MapFormatError, yaml.YAMLError):
            doc = None
        if isinstance(doc, dict) and isinstance(doc.get("image"), str):
            files.append(path.parent / doc["image"])
    return [f for f in files if f.is_file()]
