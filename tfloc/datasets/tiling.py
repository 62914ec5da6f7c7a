"""Large maps made from a small one: a vector map repeated on a grid of tiles (the scaling study).

A warehouse or campus floor is many rooms; the study needs maps of 300 to 20 000 m² whose every
part looks like the office the matchers were built on, and scans that do not change as the map
grows. :func:`tile_vector_map` repeats a map ``nx × ny`` times at a pitch of its bounding box plus
a gap (metres), so the tiles are disjoint buildings, each closed by its own outline. Tile (0, 0) is
the original, unmoved: a scan simulated in it sees only its own walls (the outline stops every
beam), so it is the same scan at every size, and a grid rasterised from any tiling has the same
cells under tile (0, 0) (the grid's frame starts at the map's lower-left corner).
:func:`tile_scans` and :func:`scan_ranges` make those scans (the protocol's sampler, seeded).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely import affinity
from shapely.geometry.base import BaseGeometry

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.errors import ConfigError
from tfloc.maps.vector import VectorMap

from .noise import NoiseModel
from .protocol import strata
from .synthetic import sample_pose_pair

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


@dataclass(frozen=True)
class TileScan:
    """One scan simulated in tile (0, 0): id, the protocol's offset cell and distance bin
    (``0-1 m``), true and initial poses (metres, radians), and the seed of its range noise."""

    scan_id: str
    cell: str
    offset_bin: str
    truth: Pose
    initial: Pose
    noise_seed: int


def tile_scans(tile: VectorMap, cells: Sequence[int], seed: int, prefix: str) -> tuple[TileScan, ...]:
    """One scan per entry of ``cells`` (indices into the protocol's 3 × 3 strata), true and
    initial poses from the protocol's sampler; seeded, ids ``<prefix><k:03d>``."""
    rng = np.random.default_rng(seed)
    cs = strata()
    out = []
    for k, c in enumerate(cells):
        truth, init = sample_pose_pair(tile, cs[c], rng)
        lo, hi = cs[c].dist_m
        out.append(TileScan(f"{prefix}{k:03d}", cs[c].label, f"{lo:g}-{hi:g} m", truth, init,
                            int(rng.integers(2**31))))
    return tuple(out)


def scan_ranges(tile: VectorMap, scan: TileScan, laser: LaserSpec) -> np.ndarray:
    """The scan's ranges (metres) for ``laser``: ray-cast on ``tile`` at the truth, plus the
    default noise from the scan's own seed (so a scan does not depend on which others are made)."""
    return NoiseModel().apply(tile.raycast(scan.truth, laser), laser, np.random.default_rng(scan.noise_seed))
