"""Success and the outcome of a localization: the one rule every run, report and note applies.

* **success**: distance error ≤ ``dist_m`` *and* orientation error ≤ ``orient_deg``
  (:class:`Thresholds`; the paper-protocol default is 10 cm and 2°);
* **no-answer**: the matcher gave no pose (it declined, raised or timed out);
* otherwise a failure, told apart by the matcher's own objective (``Matcher.score``):
  **local-optimum** if it scores the true pose lower than its answer (the search stopped short
  of a better optimum), **ambiguous** if not (its objective prefers the wrong pose).

Where a failed search ended (:func:`search_outcome`), measured from the poses alone: the
``local-optimum`` label says nothing about *where* the search stopped (with a noisy objective it
holds almost whenever the objective at the truth sits at its noise floor), so failures are also
told apart as **near** (stopped within 30 cm and 5° of the truth: a stall in the basin) and
**diverged** (ended farther from the true position than the initial guess was).

Inputs are metres and radians; the functions are vectorised (scalars or arrays alike).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

SUCCESS, LOCAL_OPTIMUM, AMBIGUOUS, NO_ANSWER = "success", "local-optimum", "ambiguous", "no-answer"
OUTCOMES = (SUCCESS, LOCAL_OPTIMUM, AMBIGUOUS, NO_ANSWER)
NEAR, DIVERGED, OTHER = "near", "diverged", "other"
SEARCH_OUTCOMES = (SUCCESS, NEAR, DIVERGED, OTHER)
NEAR_DIST_M, NEAR_ORIENT_DEG = 0.30, 5.0


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


def failure_kind(score_est: Any, score_true: Any) -> Any:
    """``local-optimum`` where the matcher's objective is lower at the truth than at its answer,
    else ``ambiguous``."""
    kind = np.where(np.asarray(score_true, dtype=float) < np.asarray(score_est, dtype=float),
                    LOCAL_OPTIMUM, AMBIGUOUS)
    return str(kind) if kind.ndim == 0 else kind


def outcome(answered: Any, dist_err_m: Any, orient_err_rad: Any, score_est: Any, score_true: Any,
            thresholds: Thresholds) -> Any:
    """The outcome of each localization (see the module notes); scores may be NaN for successes."""
    out = np.where(~np.asarray(answered, dtype=bool), NO_ANSWER,
                   np.where(thresholds.success(dist_err_m, orient_err_rad), SUCCESS,
                            failure_kind(score_est, score_true)))
    return str(out) if out.ndim == 0 else out


def search_outcome(dist_err_m: Any, orient_err_rad: Any, init_dist_err_m: Any, thresholds: Thresholds,
                   near: Thresholds = Thresholds(NEAR_DIST_M, NEAR_ORIENT_DEG)) -> Any:
    """Where each search ended (:data:`SEARCH_OUTCOMES`, the first rule that holds): ``success``
    (within ``thresholds``), ``near`` (within ``near``), ``diverged`` (farther from the true
    position than the initial guess), else ``other``; NaN errors (no answer) give ``other``."""
    d = np.asarray(dist_err_m, dtype=float)
    out = np.select([thresholds.success(d, orient_err_rad), near.success(d, orient_err_rad),
                     d > np.asarray(init_dist_err_m, dtype=float)], [SUCCESS, NEAR, DIVERGED], OTHER)
    return str(out) if out.ndim == 0 else out.astype(object)
