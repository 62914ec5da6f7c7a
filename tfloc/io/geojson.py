"""GeoJSON ↔ :class:`~tfloc.maps.vector.VectorMap` (metres).

A FeatureCollection whose LineStrings are walls and whose Polygons are obstacles or the room
outline. A feature may say which with ``properties.role`` = ``"wall" | "obstacle" | "outline"``;
without it, a polygon that covers every other feature is the outline, any other an obstacle.
"""

from __future__ import annotations

import json
from pathlib import Path

import shapely
from shapely.geometry import mapping, shape

from tfloc.errors import MapFormatError
from tfloc.maps.vector import VectorMap

from .text import parse_text

_ROLES = {"wall", "obstacle", "outline"}


def read_vector_map(path: str | Path) -> VectorMap:
    """Read a GeoJSON FeatureCollection into a VectorMap; errors name the file and feature."""
    path = Path(path)
    doc = parse_text(path, MapFormatError, "map file", json.loads, json.JSONDecodeError, "JSON")
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection":
        raise MapFormatError(f"{path}: expected a GeoJSON FeatureCollection at the top level")
    feats = doc.get("features")
    if not isinstance(feats, list) or not feats:
        raise MapFormatError(f"{path}: 'features' must be a non-empty list")
    walls, polys, outline = [], [], None
    for i, f in enumerate(feats):
        where = f"{path}: feature {i}"
        if not isinstance(f, dict) or not isinstance(f.get("geometry"), dict):
            raise MapFormatError(f"{where}: has no 'geometry' object")
        try:
            g = shape(f["geometry"])
        except Exception as exc:  # shapely raises several types for bad coordinates
            why = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise MapFormatError(f"{where}: bad geometry ({why})") from None
        if g.is_empty or not shapely.is_valid(g) or not shapely.get_coordinates(g).size:
            raise MapFormatError(f"{where}: empty or invalid {g.geom_type} ({shapely.is_valid_reason(g)})")
        props = f.get("properties") or {}
        role = props.get("role") if isinstance(props, dict) else None
        if role is not None and (not isinstance(role, str) or role not in _ROLES):
            raise MapFormatError(f"{where}: unknown role {role!r} (expected one of {sorted(_ROLES)})")
        kind = g.geom_type
        if kind in ("LineString", "MultiLineString"):
            walls.append(g)
        elif kind in ("Polygon", "MultiPolygon"):
            if role == "outline":
                outline = g
            else:
                polys.append((g, role))
        else:
            raise MapFormatError(f"{where}: unsupported geometry type {kind}")
    if outline is None:  # the polygon covering everything else, if any, is the outline
        everything = shapely.GeometryCollection([*walls, *(p for p, _ in polys)])
        for j, (p, role) in enumerate(polys):
            if role is None and p.buffer(1e-9).covers(everything):
                outline = p
                del polys[j]
                break
    return VectorMap(walls=tuple(walls), obstacles=tuple(p for p, _ in polys), outline=outline,
                     name=path.stem)


def write_vector_map(m: VectorMap, path: str | Path) -> None:
    """Write a VectorMap as GeoJSON with explicit roles (coordinates rounded to 0.1 mm)."""
    feats = []
    for role, geoms in (("outline", [m.outline] if m.outline is not None else []),
                        ("obstacle", m.obstacles), ("wall", m.walls)):
        for g in geoms:
            g = shapely.set_precision(g, 1e-4)
            feats.append({"type": "Feature", "properties": {"role": role}, "geometry": mapping(g)})
    Path(path).write_text(json.dumps({"type": "FeatureCollection", "name": m.name,
                                      "features": feats}, indent=1))
