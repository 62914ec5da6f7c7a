"""The truth-free verdict's values, in one place (metres, radians, scans).

Each was chosen on the development split (the MIT CSAIL native recording and the simulated
route-a sequences, ``benchmarks/dev/truth-free.toml``) and is reported on the rest
(docs/truth-free.md says which is which and what the choice was between).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar


@dataclass(frozen=True)
class TruthFreeConfig:
    """The rules of the truth-free verdict (module notes)."""

    RULES: ClassVar[dict] = {"> 0": ("fit_tol_m", "field_resolution_m", "agree_m", "agree_rad",
                                     "restart_offset_m", "restart_offset_rad"),
                             ">= 1": ("min_methods", "restarts", "restart_scans", "block_scans"),
                             "[0, 1]": ("fit_margin",)}

    fit_tol_m: float = 0.05  #: a return fits the map within this distance of its geometry (metres)
    field_resolution_m: float = 0.025  #: the distance field's cell for the fit (metres)
    fit_margin: float = 0.10  #: without a consensus, an answer is believed if its fit share is within this of the scan's best
    agree_m: float = 0.10  #: two answers agree within this distance (metres) ...
    agree_rad: float = math.radians(2.0)  #: ... and this heading difference (radians): the tracked thresholds
    min_methods: int = 2  #: a consensus needs this many independent methods (the tracker's own left out)
    odometry_factor: float = 2.0  #: a correction beyond this many times the recording's odometry envelope disagrees
    envelope_quantile: float = 0.99  #: the odometry envelope: this quantile of the consensus's corrections
    min_envelope_m: float = 0.05  #: the envelope is never below this (metres) ...
    min_envelope_rad: float = math.radians(1.0)  #: ... or this (radians)
    jump_m: float = 1.0  #: a correction beyond this is a jump (metres; the tracking tables' rule)
    restarts: int = 12  #: restarts per tracker and recording, spread evenly over it
    restart_scans: int = 30  #: scans a restarted tracker runs before it is compared with its trajectory
    restart_offset_m: float = 0.3  #: how far a restart is put from the tracker's own answer (metres) ...
    restart_offset_rad: float = math.radians(5.0)  #: ... and turned (radians, either way)
    block_scans: int = 50  #: the interval's bootstrap resamples blocks of this many consecutive scans
    resamples: int = 2000  #: bootstrap resamples
    seed: int = 0  #: seeds the restarts' directions and the bootstrap

    def __post_init__(self) -> None:
        from tfloc.errors import ConfigError

        for rule, keys in self.RULES.items():
            for k in keys:
                v = getattr(self, k)
                ok = v > 0 if rule == "> 0" else v >= 1 if rule == ">= 1" else 0 <= v <= 1
                if not (isinstance(v, int | float) and math.isfinite(v) and ok):
                    raise ConfigError(f"truth-free verdict: {k} must be {rule}, got {v!r}")
