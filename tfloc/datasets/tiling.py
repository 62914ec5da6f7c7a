"""Large maps made from a small one: a vector map repeated on a grid of tiles (the scaling study).

A warehouse or campus floor is many rooms; the study needs maps of 300 to 20 000 m² whose every
part looks like the office the matchers were built on, and scans that do not change as the map
grows. :func:`tile_vector_map` repeats a map ``nx × ny`` times at a pitch of its bounding box plus
a gap (metres), so the tiles are disjoint buildings, each closed by its own outline. Tile (0, 0) is
the original, unmoved: a scan simulated in it sees only its own walls (the outline stops every
beam), so it is the same scan at every size, and a grid rasterised from any tiling has the same
cells under tile (0, 0) (the grid's frame starts at the map's lower-left corner).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import shapely
from shapely import affinity
from shapely.geometry.base import BaseGeometry

from tfloc.errors import ConfigError
from tfloc.maps.vector import VectorMap

#: Metres between neighbouring tiles' bounding boxes (a wall's thickness).
DEFAULT_GAP_M = 0.4


@dataclass(frozen=True)
class Tiling:
    """How a map is repeated: ``nx × ny`` tiles at a pitch of ``(pitch_x, pitch_y)`` metres."""

    nx: int
    ny: int
    pitch_x: float
    pitch_y: float

    @property
    def tiles(self) -> int:
        return self.nx * self.ny

    @property
    def extent_m2(self) -> float:
        """The bounding box of all tiles (what a grid of the tiled map covers), m²."""
        return self.nx * self.pitch_x * self.ny * self.pitch_y


def tiling_for_area(tile: VectorMap, area_m2: float, gap_m: float = DEFAULT_GAP_M) -> Tiling:
    """The square ``n × n`` tiling of ``tile`` whose extent is nearest ``area_m2`` (log scale), n ≥ 1."""
    if not (math.isfinite(area_m2) and area_m2 > 0):
        raise ConfigError(f"map area must be a positive number of m², got {area_m2!r}")
    if gap_m < 0:
        raise ConfigError(f"tile gap must be ≥ 0 m, got {gap_m!r}")
    x0, y0, x1, y1 = tile.bounds
    px, py = x1 - x0 + gap_m, y1 - y0 + gap_m
    n = max(1, round(math.sqrt(area_m2 / (px * py))))
    return Tiling(n, n, px, py)


def _moved(geoms: tuple[BaseGeometry, ...], dx: float, dy: float) -> list[BaseGeometry]:
    return [affinity.translate(g, dx, dy) for g in geoms]


def _union(polygons: list[BaseGeometry]) -> BaseGeometry | None:
    """Disjoint polygons as one (Multi)Polygon; ``None`` for none."""
    if not polygons:
        return None
    parts = [p for g in polygons for p in shapely.get_parts(g)]
    return parts[0] if len(parts) == 1 else shapely.multipolygons(parts)


def tile_vector_map(tile: VectorMap, tiling: Tiling, name: str | None = None) -> VectorMap:
    """``tile`` repeated as ``tiling`` says: walls and obstacles copied into every tile, the
    outline (or region) a MultiPolygon of the tiles' outlines. Tile (0, 0) is ``tile`` itself."""
    if tile.outline is None and tile.region is None:
        raise ConfigError(f"map {tile.name!r}: tiling needs an outline or a region (the tiles must be closed)")
    walls, obstacles, outlines, regions = [], [], [], []
    for j in range(tiling.ny):
        for i in range(tiling.nx):
            dx, dy = i * tiling.pitch_x, j * tiling.pitch_y
            walls += _moved(tile.walls, dx, dy)
            obstacles += _moved(tile.obstacles, dx, dy)
            if tile.outline is not None:
                outlines += _moved((tile.outline,), dx, dy)
            if tile.region is not None:
                regions += _moved((tile.region,), dx, dy)
    return VectorMap(walls=tuple(walls), obstacles=tuple(obstacles),
                     outline=_union(outlines), region=_union(regions),
                     name=name or f"{tile.name}x{tiling.nx}x{tiling.ny}")
