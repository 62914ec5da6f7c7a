"""The peers' tracking configurations: ``karto-gated`` matches only when slam_toolbox's gate passes
(time, √0.8 × the travel distance, the scan counter; never for a turn in place), and
``kiss-icp-adaptive`` gates its ICP by KISS-ICP's own adaptive threshold of the deviations it saw."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _baseline_cases import make_problem

import tfloc
from tfloc import Estimate, Pose
from tfloc.core.presets import preset_params


class _Counting:
    """A stand-in for Karto: answers the guess and counts the calls."""

    name = "counting"

    def __init__(self) -> None:
        self.calls = 0

    def localize(self, problem) -> Estimate:  # noqa: ANN001
        self.calls += 1
        return Estimate(problem.initial, True)


def _gated(**params):
    try:
        tracker = tfloc.get_matcher("karto-gated", **params)
    except tfloc.MatcherError as exc:  # karto-scanmatcher missing (Python ≥ 3.12)
        pytest.skip(str(exc))
    tracker.matcher = _Counting()
    return tracker


def test_the_gate_is_slam_toolboxs_should_process_scan() -> None:
    problem, true = make_problem()
    t = _gated()
    t.start(problem.map, problem.laser, true)
    matched = []
    steps = [(Pose(0.1, 0.0, 0.0), 0.11)] * 12 + [(Pose(0.0, 0.0, 0.3), 0.1)] * 10 + [(Pose(0.5, 0.0, 0.0), 0.2)] * 3
    stamp = 0.0
    for delta, dt in steps:
        stamp += dt
        matched.append(t.step(problem.ranges, delta, stamp).info["matched"])
    # first scan: passes but is not matched; then 0.1 m per 0.11 s: the 5th scan has moved 0.4 m,
    # under √0.8 × 0.5 = 0.447 m; the 6th (0.5 m, 0.55 s, counter 6) is matched, and every 5th after
    assert [i for i, m in enumerate(matched[:12]) if m] == [5, 10]
    assert not any(matched[12:22])  # a turn in place of 3 rad is never matched
    # then 0.5 m steps, the odometry's displacement since the last match counted: the 0.1 m driven
    # before the 3 rad turn points back, so 0.4 m (no), 0.9 m (yes), then 0.5 m after 0.2 s (no)
    assert matched[22:] == [False, True, False]
    assert t.matcher.calls == sum(matched)


def test_the_gate_throttles_and_waits_for_time() -> None:
    problem, true = make_problem()
    t = _gated(throttle_scans=2, minimum_time_interval=1.0)
    t.start(problem.map, problem.laser, true)
    out = [t.step(problem.ranges, Pose(1.0, 0.0, 0.0), 0.4 * (k + 1)).info["matched"] for k in range(10)]
    # counter ≥ 5, even, ≥ 1 s after the last processed scan (the first, at 0.4 s): scans 6 and 10
    assert [k + 1 for k, m in enumerate(out) if m] == [6, 10]


def test_between_matches_the_pose_is_carried_by_the_odometry() -> None:
    problem, true = make_problem()
    t = _gated()
    t.start(problem.map, problem.laser, true)
    est = t.step(problem.ranges, Pose(0.05, 0.01, 0.02), 0.1)
    assert est.pose == true.compose(Pose(0.05, 0.01, 0.02)) and est.converged


def test_karto_track_is_slam_toolboxs_localization_configuration() -> None:
    p = preset_params("karto-track")
    assert p["local"]["coarse"] is False
    assert (p["local"]["fine_search_size"], p["local"]["fine_resolution"], p["local"]["fine_smear_deviation"]) == (
        0.5, 0.01, 0.1)
    assert p["minimum_travel_distance"] == 0.5 and p["minimum_time_interval"] == 0.5


def test_kiss_icp_adaptive_uses_kiss_icps_threshold() -> None:
    problem, true = make_problem()
    t = tfloc.get_matcher("kiss-icp-adaptive")
    t.start(problem.map, problem.laser, true)
    rng = np.random.default_rng(2)
    ranges = lambda pose: problem.map.raycast(pose, problem.laser) + rng.normal(0, 0.01, problem.laser.n_beams)  # noqa: E731
    est = t.step(ranges(true), Pose(), 0.0)
    assert est.info["sigma"] == pytest.approx(2.0)  # initial_threshold
    assert est.pose.distance_to(true) < 0.02
    # the odometry claims 0.2 m that the robot did not drive: ICP corrects it, and the deviation
    # (above min_motion_th) enters the threshold: σ² = (2² + e²) / 2, e = ‖Δt‖ + 2·r·sin(Δθ/2)
    est2 = t.step(ranges(true), Pose(0.2, 0.0, 0.0), 0.1)
    assert est2.pose.distance_to(true) < 0.02
    pred = est.pose.compose(Pose(0.2, 0.0, 0.0))
    dev = pred.between(est2.pose)
    e = math.hypot(dev.x, dev.y) + 2.0 * problem.laser.max_range * abs(math.sin(dev.theta / 2.0))
    est3 = t.step(ranges(true), Pose(), 0.2)
    assert est3.info["sigma"] == pytest.approx(math.sqrt((4.0 + e**2) / 2.0), rel=1e-3)
