"""Scoring kidnap events: how long a tracker takes to find itself again, and when it jumps wrongly.

Inputs are one tracked sequence's estimates, truths and predictions (``(N, 3)`` SE(2) arrays,
metres and radians, in scan order; the prediction is what the tracking loop handed the matcher,
the ``init_*`` columns) and the **kidnap scans** (positions in the sequence of the first scan
after each event, from ``scenario.json`` ``"kidnaps"``). A scan is *correct* when its error is
within the success thresholds (:class:`~tfloc.evaluation.outcome.Thresholds`, default 10 cm, 2°).

* **scans to relocalize** (per event): ``k − e`` for the first scan ``k ≥ e`` after the event
  ``e`` that is correct and stays correct for :data:`HOLD` scans in a row (fewer if the sequence
  or the event's window ends first); ``None`` ("never") when no such scan comes before the next
  event or the end. An event is **recovered within** ``n`` scans when that count is ≤ ``n``.
* **false relocalization**: a scan whose estimate lies more than :data:`JUMP_M` from its
  prediction although the previous estimate was correct, and is not correct itself (a jump away
  from a correct pose). A jump onto the truth is not one, nor is a jump at a kidnap scan (the
  previous estimate was right for where the robot was, not for where it is).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tfloc.core.thresholds import Thresholds

from .trajectory import errors

#: scans an estimate must stay correct for to count as relocalized
HOLD = 3
#: a jump of the estimate away from its prediction larger than this (metres) is a relocalization
JUMP_M = 1.0
#: the target: relocalized within this many scans after every kidnap
WITHIN = 20
DEFAULT = Thresholds()


@dataclass(frozen=True)
class KidnapScore:
    """One sequence's kidnap scores: ``scans_to_relocalize`` per event (``None`` = never) and the
    scans of false relocalizations (positions in the sequence)."""

    events: tuple[int, ...]
    scans_to_relocalize: tuple[int | None, ...]
    false_relocalizations: tuple[int, ...]

    def recovered_within(self, n: int = WITHIN) -> int:
        """Events relocalized within ``n`` scans."""
        return sum(s is not None and s <= n for s in self.scans_to_relocalize)


def correct(est: np.ndarray, true: np.ndarray, thresholds: Thresholds = DEFAULT) -> np.ndarray:
    """Per scan: within the success thresholds (False where the truth is missing)."""
    est, true = np.asarray(est, float).reshape(-1, 3), np.asarray(true, float).reshape(-1, 3)
    ok = np.zeros(len(est), dtype=bool)
    has = np.isfinite(true).all(axis=1) & np.isfinite(est).all(axis=1)
    if has.any():
        d, o = errors(est[has], true[has])
        ok[has] = thresholds.success(d, o)
    return ok


def scans_to_relocalize(ok: np.ndarray, events: Sequence[int], hold: int = HOLD) -> list[int | None]:
    """Per event (module notes): scans from the event to the first correct scan that stays
    correct for ``hold`` scans within the event's window, or ``None``."""
    ok = np.asarray(ok, dtype=bool)
    ev = sorted(int(e) for e in events)
    out: list[int | None] = []
    for i, e in enumerate(ev):
        end = ev[i + 1] if i + 1 < len(ev) else len(ok)
        found = None
        for k in np.flatnonzero(ok[e:end]) + e:
            if ok[k:min(k + hold, end)].all():
                found = int(k - e)
                break
        out.append(found)
    return out


def false_relocalizations(est: np.ndarray, pred: np.ndarray, ok: np.ndarray,
                          events: Sequence[int] = (), jump_m: float = JUMP_M) -> list[int]:
    """Scans (other than the kidnap scans ``events``) whose estimate jumped more than ``jump_m``
    from its prediction away from a correct previous estimate to an incorrect one (module notes)."""
    est, pred = np.asarray(est, float).reshape(-1, 3), np.asarray(pred, float).reshape(-1, 3)
    jump = np.hypot(est[:, 0] - pred[:, 0], est[:, 1] - pred[:, 1])
    jump = np.where(np.isfinite(jump), jump, 0.0)
    hit = np.zeros(len(est), dtype=bool)
    hit[1:] = (jump[1:] > jump_m) & ok[:-1] & ~ok[1:]
    hit[[int(e) for e in events if 0 <= int(e) < len(hit)]] = False
    return [int(k) for k in np.flatnonzero(hit)]


def score_kidnaps(est: np.ndarray, true: np.ndarray, pred: np.ndarray, events: Sequence[int],
                  thresholds: Thresholds = DEFAULT) -> KidnapScore:
    """Every kidnap score of one sequence (module notes)."""
    ok = correct(est, true, thresholds)
    return KidnapScore(tuple(sorted(int(e) for e in events)),
                       tuple(scans_to_relocalize(ok, events)),
                       tuple(false_relocalizations(est, pred, ok, events)))


def median_scans(values: Sequence[int | None]) -> float:
    """The median of scans to relocalize over events, "never" counted as infinitely many
    (``inf`` when half or more never relocalized; NaN without events)."""
    if not values:
        return math.nan
    return float(np.median([math.inf if v is None else float(v) for v in values]))
