"""What a scaling study runs: :class:`StudyConfig`, every field of which decides its rows.

Axes (each level one problem set, every matcher on the same scans; :mod:`tfloc.harness.scaling_levels`):

* ``area``: the tile map (default the office floor ``data/maps/office-1.geojson``) tiled to about
  300, 1 200, 5 000 and 20 000 m² (:mod:`tfloc.datasets.tiling`), as a vector map and as a 5 cm
  grid; the scans lie in tile (0, 0), so only the map grows. LMS200 (181 beams).
* ``beams``: 181, 361, 721 beams (180° at 1°, 0.5°, 0.25°) and 1081 (270° at 0.25°), the same
  true and initial poses on the one-tile vector map.
* ``offset``: initial distance offsets in the protocol's bins 0–1, 1–2, 2–3 m (angle offsets in
  its three bins in turn), one-tile vector map, 181 beams.

Budgets: a matcher over ``budget_ms`` (median CPU) or ``prep_budget_s`` at a level is not run at
the larger levels of that axis and map kind (:func:`tfloc.evaluation.scaling.over_budget`).
A study file's ``[scaling]`` table holds these fields (:meth:`StudyConfig.from_dict`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any

from tfloc.core.thresholds import Thresholds
from tfloc.errors import ConfigError

SEED = 20261201
AXES = ("area", "beams", "offset")
KINDS = ("vector", "grid")
THRESHOLDS = Thresholds()  # success: ≤ 10 cm and ≤ 2°
Log = Callable[[str], None]
Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class StudyConfig:
    """What the study runs: the tile map, sizes (m²), map kinds, lasers as (field of view °,
    resolution °), range (m), grid resolution (m), scans per level, matchers (``()``: every
    registered single-scan local matcher), budgets (ms per scan, s of preparation), warm-up calls,
    seed and axes. Every field decides rows: all of it is the study's fingerprint."""

    map_path: str = "data/maps/office-1.geojson"
    areas_m2: tuple[float, ...] = (300.0, 1200.0, 5000.0, 20000.0)
    kinds: tuple[str, ...] = KINDS
    lasers: tuple[tuple[float, float], ...] = ((180.0, 1.0), (180.0, 0.5), (180.0, 0.25), (270.0, 0.25))
    max_range_m: float = 10.0
    resolution_m: float = 0.05
    scans_per_level: int = 45          # area and beam axes: 5 per offset cell
    scans_per_offset_bin: int = 30     # offset axis: 10 per cell of each distance bin
    matchers: tuple[str, ...] = ()
    budget_ms: float = 250.0
    prep_budget_s: float = 120.0
    warmup: int = 1
    seed: int = SEED
    axes: tuple[str, ...] = AXES

    def __post_init__(self) -> None:
        bad = ([f"axis {a!r}" for a in self.axes if a not in AXES] + ([] if self.axes else ["axes (none)"])
               + [f"map kind {k!r}" for k in self.kinds if k not in KINDS]
               + [f"{n} {v!r} (must be ≥ 1)" for n, v in (("scans per level", self.scans_per_level),
                                                          ("scans per offset bin", self.scans_per_offset_bin))
                  if v < 1]
               + [f"{n} {v!r} (must be > 0)" for n, v in (("range", self.max_range_m),
                                                          ("grid resolution", self.resolution_m)) if not v > 0]
               + ([f"warm-up {self.warmup!r} (must be ≥ 0)"] if self.warmup < 0 else []))
        if bad:
            raise ConfigError("scaling study: bad " + ", ".join(bad) + f" (axes: {', '.join(AXES)}; "
                              f"kinds: {', '.join(KINDS)})")

    @classmethod
    def quick(cls) -> StudyConfig:
        """The ``make bench`` subsample: every axis and level, 9 scans per level (one per offset
        cell), 9 per offset bin (3 per cell), tighter budgets."""
        return cls(scans_per_level=9, scans_per_offset_bin=9, budget_ms=150.0, prep_budget_s=60.0)

    @classmethod
    def from_dict(cls, table: dict[str, Any], base: StudyConfig | None = None) -> StudyConfig:
        """``base`` (default: the full study) with the fields of ``table`` (a study file's
        ``[scaling]`` table, or ``run.json``'s ``config.scaling``; lists become tuples). An
        unknown field or a value of the wrong type is a :class:`ConfigError` naming it."""
        names = {f.name: f for f in fields(cls)}
        unknown = [k for k in table if k not in names]
        if unknown:
            raise ConfigError(f"scaling study: unknown field(s) {', '.join(map(repr, unknown))} "
                              f"(fields: {', '.join(names)})")
        base, like = base or cls(), cls()
        kw = {}
        for k, v in table.items():
            try:
                kw[k] = _like(getattr(like, k), v)
            except TypeError:
                raise ConfigError(f"scaling study: field {k!r} is {v!r}, not like {getattr(like, k)!r}") from None
        return cls(**{**{n: getattr(base, n) for n in names}, **kw})


def _like(default: Any, v: Any) -> Any:
    """``v`` as a value of ``default``'s type (a list as a tuple of values like the default's
    first, or of strings); TypeError if it cannot be."""
    if isinstance(default, tuple):
        if not isinstance(v, list | tuple):
            raise TypeError(v)
        return tuple(_like(default[0] if default else "", x) for x in v)
    if isinstance(default, bool) or isinstance(v, bool):
        raise TypeError(v)
    if isinstance(default, float) and isinstance(v, int | float):
        return float(v)
    if isinstance(default, int) and isinstance(v, int):
        return v
    if isinstance(default, str) and isinstance(v, str):
        return v
    raise TypeError(v)
