"""Scoring a tracker started without a pose: how long until it has found the robot, and whether it
first settled on a wrong place.

Inputs are one tracked sequence's estimates and truths (``(N, 3)`` SE(2) arrays, metres and
radians, in scan order, NaN where the truth is unknown) and where the start's window ends (the
first kidnap scan, else the end): a later event is another problem (:mod:`.kidnap`).

* **scans to converge**: the first scan ``k`` of the window whose estimate is within the success
  thresholds (10 cm, 2°) and stays within them for :data:`~.kidnap.HOLD` scans in a row (fewer if
  the window ends first); ``None`` ("never") if none. The same rule as scans to relocalize, with
  the start as the event.
* **settled**: the first scan ``s`` from which the estimate stays within :data:`SETTLE_M` of one
  place for :data:`SETTLE_SCANS` scans, the place carried along by the robot's true motion
  (``est(s) ⊕ true(s)⁻¹ · true(k)``: for a robot standing still, one point of the map). It settled
  on a **wrong** place when its error at ``s`` is a loss's (above 0.5 m or 10°,
  :mod:`.trajectory`).
* A recording whose truth is known at some scans only (a native-rate log: the corrected scans)
  is scored on those scans: ``HOLD`` and ``SETTLE_SCANS`` count truth-bearing scans, and the
  scan numbers reported are the recording's own.
* **starts without a pose**: what the tracker itself says in its first row's ``info``
  (``"start": "global"``: it ignored the pose the harness passed), never the label's name.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from tfloc.core.thresholds import Thresholds
from tfloc.core.tracker import GLOBAL_START, START_KEY

from .kidnap import DEFAULT, HOLD, correct, scans_to_relocalize
from .trajectory import LOST_DIST_M, LOST_ORIENT_DEG, errors

#: a settled estimate stays within this distance (metres) of one place ...
SETTLE_M = 0.5
#: ... for this many scans in a row
SETTLE_SCANS = 10


@dataclass(frozen=True)
class StartScore:
    """One sequence's start from no pose (module notes): ``scans_to_converge`` (``None`` = never),
    the scan it first ``settled`` at (``None`` = never) and whether that place was ``wrong``."""

    window: int
    scans_to_converge: int | None
    settled: int | None
    wrong: bool


def starts_without_pose(first_info: Mapping) -> bool:
    """Whether a tracker says, in its first row's ``info``, that it started without a pose."""
    return first_info.get(START_KEY) == GLOBAL_START


def scans_to_converge(ok: np.ndarray, end: int | None = None, hold: int = HOLD) -> int | None:
    """Scans from the start to the first correct scan (``ok``) that stays correct for ``hold``
    scans before ``end``; ``None`` if none."""
    ok = np.asarray(ok, dtype=bool)[:end]
    return scans_to_relocalize(ok, [0], hold)[0] if len(ok) else None


def carried(est: np.ndarray, true: np.ndarray, s: int) -> np.ndarray:
    """The place ``est[s]`` carried along by the true motion: ``est[s] ⊕ true[s]⁻¹ · true[k]``
    for every ``k`` (``(N, 3)``, metres and radians)."""
    est, true = np.asarray(est, float).reshape(-1, 3), np.asarray(true, float).reshape(-1, 3)
    c, s_ = np.cos(true[s, 2]), np.sin(true[s, 2])
    dx, dy = true[:, 0] - true[s, 0], true[:, 1] - true[s, 1]
    lx, ly = c * dx + s_ * dy, -s_ * dx + c * dy  # true motion in the robot frame at s
    ce, se = np.cos(est[s, 2]), np.sin(est[s, 2])
    return np.column_stack([est[s, 0] + ce * lx - se * ly, est[s, 1] + se * lx + ce * ly,
                            est[s, 2] + (true[:, 2] - true[s, 2])])


def first_settled(est: np.ndarray, true: np.ndarray, end: int | None = None, radius_m: float = SETTLE_M,
                  scans: int = SETTLE_SCANS) -> int | None:
    """The first scan from which the estimate stays within ``radius_m`` of one place (carried by
    the true motion) for ``scans`` scans before ``end``; ``None`` if none (module notes)."""
    est = np.asarray(est, float).reshape(-1, 3)[:end]
    true = np.asarray(true, float).reshape(-1, 3)[:end]
    has = np.isfinite(true).all(axis=1) & np.isfinite(est).all(axis=1)
    for s in range(len(est) - scans + 1):
        if not has[s:s + scans].all():
            continue
        place = carried(est[s:s + scans], true[s:s + scans], 0)
        if (np.hypot(*(est[s:s + scans, :2] - place[:, :2]).T) <= radius_m).all():
            return s
    return None


def score_start(est: np.ndarray, true: np.ndarray, end: int | None = None,
                thresholds: Thresholds = DEFAULT) -> StartScore:
    """Every start score of one sequence, its window ending before scan ``end`` (module notes)."""
    est, true = np.asarray(est, float).reshape(-1, 3), np.asarray(true, float).reshape(-1, 3)
    window = len(est) if end is None else min(int(end), len(est))
    scored = np.flatnonzero(np.isfinite(true[:window]).all(axis=1))  # the truth-bearing scans
    e, t = est[scored], true[scored]
    ok = correct(e, t, thresholds)
    s = first_settled(e, t)
    wrong = False
    if s is not None:
        d, o = errors(e[s:s + 1], t[s:s + 1])
        wrong = bool(d[0] > LOST_DIST_M or np.degrees(o[0]) > LOST_ORIENT_DEG)
    k = scans_to_converge(ok)
    return StartScore(window, None if k is None else int(scored[k]),
                      None if s is None else int(scored[s]), wrong)
