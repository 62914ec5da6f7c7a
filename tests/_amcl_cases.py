"""What the tests of the two AMCL trackers share (``amcl``: ``tests/baselines/test_amcl.py``,
``amcl-wheel``: ``test_amcl_wheel.py``): the laser, the initial spread, the office-1 corridor and
a run along a path with scans ray-cast in the grid AMCL gets and exact odometry."""

from __future__ import annotations

import math

import numpy as np
from tfloc.baselines._amcl_common import amcl_grid

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose

LASER = LaserSpec.lms200()
#: the initial cloud of the spread starts: 0.5 m in x and y, 15° in heading (standard deviations)
SPREAD = {"initial_sigma_xy": 0.5, "initial_sigma_theta": math.radians(15.0)}


def run_along(tracker, vmap, truth: list[Pose], start: Pose) -> tuple[np.ndarray, list, object]:
    """``tracker`` started on ``vmap`` at ``start`` and stepped along ``truth`` (10 Hz stamps): the
    position errors (m), the estimates and the tracker."""
    scans = amcl_grid(vmap).raycast(np.array([p.as_array() for p in truth]), LASER)
    tracker.start(vmap, LASER, start)
    ests = [tracker.step(scans[k], truth[k - 1].between(p) if k else Pose(), 0.1 * k)
            for k, p in enumerate(truth)]
    return np.array([e.pose.distance_to(p) for e, p in zip(ests, truth, strict=True)]), ests, tracker


def corridor(n: int = 170) -> list[Pose]:
    """East along the office-1 corridor (y = 7.5 m, columns and doors on both sides), 0.1 m a scan."""
    return [Pose(1.0 + 0.1 * k, 7.5, 0.0) for k in range(n)]
