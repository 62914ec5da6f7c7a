"""The scaling study's problem sets: one :class:`Level` per (axis, map kind, size), in the order
the study runs them (area, beams, offset; :mod:`tfloc.harness.scaling_config`).

Scans: :func:`tfloc.datasets.tiling.tile_scans`, ray-cast on the tile plus 1 cm noise, seeded
(``StudyConfig.seed``): the area axis's scans are the same at every size, the beam axis's the
same poses at every laser; initial poses from the protocol's sampler, scan k in offset cell k
mod 9 (the offset axis: three cells of one distance bin per level).
"""

from __future__ import annotations

from dataclasses import dataclass

from tfloc.core.laser import LaserSpec
from tfloc.datasets.tiling import TileScan, Tiling, tile_scans, tiling_for_area
from tfloc.maps.vector import VectorMap

from .scaling_config import StudyConfig

OFFSET_BINS = ("0-1 m", "1-2 m", "2-3 m")
OFFSET_MID_M = (0.5, 1.5, 2.5)


@dataclass(frozen=True)
class Level:
    """One problem set: its axis, map kind, label, x (``size``: m², beams or metres), laser,
    scans and tiling of the map."""

    axis: str
    kind: str
    level: str
    size: float
    laser: LaserSpec
    scans: tuple[TileScan, ...]
    tiling: Tiling

    @property
    def key(self) -> str:
        """``axis/kind/level``: the level's name in ``run.json`` (``levels``, ``done``)."""
        return f"{self.axis}/{self.kind}/{self.level}"


def laser_of(fov_deg: float, resolution_deg: float, max_range_m: float) -> LaserSpec:
    """A laser centred on the heading: 180° at 1° is the LMS200 (181 beams)."""
    return LaserSpec.from_degrees(max_range_m, fov_deg, resolution_deg)


def study_levels(cfg: StudyConfig, tile: VectorMap) -> list[Level]:
    """Every problem set of the study, in the order it runs (area, beams, offset); sizes that
    round to the same tiling are one level."""
    lms = laser_of(180.0, 1.0, cfg.max_range_m)
    one = tiling_for_area(tile, 1.0)
    levels: list[Level] = []
    if "area" in cfg.axes:
        scans = tile_scans(tile, [k % 9 for k in range(cfg.scans_per_level)], cfg.seed, "a")
        tilings = list(dict.fromkeys(tiling_for_area(tile, a) for a in cfg.areas_m2))
        levels += [Level("area", kind, f"{t.nx}x{t.ny}", t.extent_m2, lms, scans, t)
                   for kind in cfg.kinds for t in tilings]
    if "beams" in cfg.axes:
        scans = tile_scans(tile, [k % 9 for k in range(cfg.scans_per_level)], cfg.seed + 1, "b")
        for fov, res in cfg.lasers:
            laser = laser_of(fov, res, cfg.max_range_m)
            levels.append(Level("beams", "vector", f"{laser.n_beams} ({fov:g}°/{res:g}°)", laser.n_beams,
                                laser, scans, one))
    if "offset" in cfg.axes:
        n = cfg.scans_per_offset_bin
        for b, (label, mid) in enumerate(zip(OFFSET_BINS, OFFSET_MID_M, strict=True)):
            scans = tile_scans(tile, [3 * b + k % 3 for k in range(n)], cfg.seed + 2 + b, f"o{b}-")
            levels.append(Level("offset", "vector", label, mid, lms, scans, one))
    return levels
