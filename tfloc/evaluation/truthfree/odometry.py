"""Agreement with the odometry: how far each answer moved from the odometry's prediction.

A tracker's *correction* at a scan is the distance (metres) and heading difference (radians)
between its answer and the prediction it started from (its last answer carried by the odometry
increment: the row's ``init_*``). A good tracker corrects by about the odometry's own error; the
recording's odometry *envelope* is a quantile of the corrections of the answers the other
signals back (the consensus where there is one, else a fit near the scan's best: what the
odometry's error looks like to answers that are believed), never below a floor. A
correction beyond ``factor`` × the envelope disagrees with the odometry; beyond ``jump_m`` it is a
jump. Dead reckoning never disagrees: this signal only ever counts against a tracker.
"""

from __future__ import annotations

import math

import numpy as np


def corrections(est: np.ndarray, init: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance (metres) and absolute heading difference (radians) between ``est`` and ``init``
    (``(..., 3)`` each)."""
    d = np.hypot(est[..., 0] - init[..., 0], est[..., 1] - init[..., 1])
    a = np.abs((est[..., 2] - init[..., 2] + math.pi) % (2 * math.pi) - math.pi)
    return d, a


def envelope(dist: np.ndarray, turn: np.ndarray, backed: np.ndarray, quantile: float,
             floor_m: float, floor_rad: float) -> tuple[float, float]:
    """The recording's odometry envelope (metres, radians): the ``quantile`` of the corrections
    where ``backed`` (answers the consensus backs), at least the floors."""
    d, a = dist[backed], turn[backed]
    d, a = d[np.isfinite(d)], a[np.isfinite(a)]
    em = float(np.quantile(d, quantile)) if d.size else floor_m
    ea = float(np.quantile(a, quantile)) if a.size else floor_rad
    return max(em, floor_m), max(ea, floor_rad)


def disagrees(dist: np.ndarray, turn: np.ndarray, env: tuple[float, float], factor: float) -> np.ndarray:
    """Whether each correction lies beyond ``factor`` × the envelope ``env`` (either part)."""
    return (dist > factor * env[0]) | (turn > factor * env[1])
