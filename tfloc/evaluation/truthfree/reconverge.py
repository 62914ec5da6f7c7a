"""Re-convergence: restarted from a perturbed pose, does a tracker come back to its own trajectory?

At ``restarts`` scans spread evenly over a recording (never in its last ``restart_scans``), the
tracker is started afresh at its own answer there moved ``restart_offset_m`` in a seeded random
direction and turned ``restart_offset_rad`` either way, and run over the next ``restart_scans``
scans with the recording's odometry (:mod:`tfloc.harness.restarts`). It *returns* when its last
answer agrees with its own trajectory's answer at that scan (the tracked thresholds). A tracker
whose trajectory attracts nearby starts is self-consistent; dead reckoning never returns. The
signal is reported beside the verdict, which does not count it (docs/truth-free.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tfloc.core.pose import Pose


@dataclass(frozen=True)
class Restart:
    """One restart: at scan index ``first`` (0-based), from the tracker's answer there composed
    with ``offset`` (metres, radians in its own frame), run to scan index ``last``."""

    first: int
    last: int
    offset: Pose


def plan(n_scans: int, restarts: int, scans: int, offset_m: float, offset_rad: float,
         seed: int) -> tuple[Restart, ...]:
    """The restarts of a recording of ``n_scans`` (module notes); none if it is too short."""
    span = n_scans - scans
    if span < 1 or restarts < 1:
        return ()
    firsts = sorted({int(round(v)) for v in np.linspace(0, span - 1, restarts)})
    rng = np.random.default_rng(seed)
    out = []
    for k in firsts:
        a = float(rng.uniform(-math.pi, math.pi))
        turn = offset_rad if rng.random() < 0.5 else -offset_rad
        out.append(Restart(k, k + scans - 1, Pose(offset_m * math.cos(a), offset_m * math.sin(a), turn)))
    return tuple(out)


def returned(end: np.ndarray, own: np.ndarray, agree_m: float, agree_rad: float) -> np.ndarray:
    """Whether each restart's last answer ``end`` ``(R, 3)`` agrees with the tracker's own answer
    ``own`` ``(R, 3)`` at that scan (non-finite: did not return)."""
    d = np.hypot(end[:, 0] - own[:, 0], end[:, 1] - own[:, 1])
    a = np.abs((end[:, 2] - own[:, 2] + math.pi) % (2 * math.pi) - math.pi)
    return np.isfinite(d) & (d <= agree_m) & (a <= agree_rad)
