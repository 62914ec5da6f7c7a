"""The success thresholds of a run: a value every layer reads (run configurations, run
directories, workers, metrics and notes). The rule that applies them is
:mod:`tfloc.evaluation.outcome`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Thresholds:
    """Success: distance error ≤ ``dist_m`` (metres) and orientation error ≤ ``orient_deg`` (°)."""

    dist_m: float = 0.10
    orient_deg: float = 2.0

    @property
    def orient_rad(self) -> float:
        """The orientation threshold in radians."""
        return math.radians(self.orient_deg)

    def success(self, dist_err_m: Any, orient_err_rad: Any) -> Any:
        """Whether errors (metres, radians; the sign of the angle is ignored) are a success.
        NaN errors are not."""
        d = np.asarray(dist_err_m, dtype=float)
        o = np.degrees(np.abs(np.asarray(orient_err_rad, dtype=float)))
        ok = (d <= self.dist_m) & (o <= self.orient_deg)
        return bool(ok) if ok.ndim == 0 else ok

    def to_dict(self) -> dict[str, float]:
        """The ``[success]`` table of a run configuration and of ``run.json``."""
        return {"dist_m": self.dist_m, "orient_deg": self.orient_deg}

    @classmethod
    def from_dict(cls, doc: dict | None) -> Thresholds:
        """Read a ``[success]`` table (defaults for missing keys)."""
        doc = doc or {}
        return cls(float(doc.get("dist_m", cls.dist_m)), float(doc.get("orient_deg", cls.orient_deg)))

    @classmethod
    def from_run(cls, run: dict) -> Thresholds:
        """The thresholds recorded in a ``run.json`` document (defaults if absent)."""
        return cls.from_dict(run.get("config", {}).get("success"))
