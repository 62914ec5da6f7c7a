"""Shared fixtures for the baseline tests: a known 0.3 m / 5° offset in the bundled test room."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import tfloc
from tfloc import LaserSpec, Pose, Problem, angdiff

MAP_PATH = Path(__file__).resolve().parents[1] / "data" / "maps" / "test-room.geojson"
TRUE_POSE = Pose(4.0, 3.0, 0.3)  # sees the outer walls, the L-shaped notch and two obstacles
# (direction of the 0.3 m offset in the robot frame, sign of the 5° offset)
OFFSETS = [(0.0, 1.0), (math.radians(135.0), -1.0), (math.radians(250.0), 1.0)]


def test_map():
    return tfloc.load_map(MAP_PATH)


def make_problem(direction: float = 0.0, sign: float = 1.0, seed: int = 7,
                 true: Pose = TRUE_POSE) -> tuple[Problem, Pose]:
    """The real scan from ``true`` (+ N(0, 1 cm) noise) and initial = true ⊕ (0.3 m, ±5°)."""
    m = test_map()
    laser = LaserSpec.lms200()
    ranges = m.raycast(true, laser)
    ranges = ranges + np.random.default_rng(seed).normal(0.0, 0.01, ranges.shape)
    offset = Pose(0.3 * math.cos(direction), 0.3 * math.sin(direction), sign * math.radians(5.0))
    return Problem(m, laser, ranges, true.compose(offset)), true


def errors(estimate_pose: Pose, true: Pose) -> tuple[float, float]:
    """(distance error m, orientation error degrees)."""
    return estimate_pose.distance_to(true), abs(math.degrees(angdiff(estimate_pose.theta, true.theta)))
