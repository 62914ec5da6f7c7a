"""One scan of a dataset, as every layer takes it: the real scan, its initial guess, its true
pose where known, its stamp and the robot's raw odometry there (metres, radians, seconds).
:mod:`tfloc.io.scenario` reads them from ``scans.csv``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .pose import Pose


@dataclass(frozen=True, eq=False)
class Scan:
    """One row of ``scans.csv``: the real scan, its initial guess and (maybe) its true pose."""

    scan_id: str
    group: str
    ranges: np.ndarray
    initial: Pose | None  # None: a global problem, or a sequence row after the first
    true: Pose | None = None
    line: int = 0  # 1-based line in scans.csv, for messages
    ref_ranges: np.ndarray | None = None  # scan-to-scan datasets: the reference scan (see map_for)
    stamp: float | None = None  # seconds (optional ``stamp`` column), e.g. the ROS header stamp
    odom: Pose | None = None  # sequences: the raw odometry pose at this scan (odometry frame)
