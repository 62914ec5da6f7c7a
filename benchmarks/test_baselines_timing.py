"""pytest-benchmark timings of one ``localize`` per baseline on the test room (0.3 m / 5° offset).

Run: ``PYTHONPATH=$PWD pytest benchmarks/test_baselines_timing.py --benchmark-only``
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import tfloc
from tfloc import LaserSpec, Pose, Problem

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def problem() -> Problem:
    m = tfloc.load_map(ROOT / "data" / "maps" / "test-room.geojson")
    laser = LaserSpec.lms200()
    true = Pose(4.0, 3.0, 0.3)
    ranges = m.raycast(true, laser) + np.random.default_rng(7).normal(0.0, 0.01, laser.n_beams)
    return Problem(m, laser, ranges, true.compose(Pose(0.3, 0.0, math.radians(5.0))))


def _needs(module: str) -> pytest.MarkDecorator:
    return pytest.mark.skipif(importlib.util.find_spec(module) is None, reason=f"{module} is not installed")


@pytest.mark.parametrize("name", ["o3d-icp", "kiss-icp", "csm-corr", "cv-corners",
                                  pytest.param("gicp", marks=_needs("small_gicp")),
                                  pytest.param("karto", marks=_needs("karto_scanmatcher"))])
def test_localize_time(benchmark, problem: Problem, name: str) -> None:  # noqa: ANN001
    matcher = tfloc.get_matcher(name)
    matcher.localize(problem)  # build the per-map caches outside the timing
    est = benchmark(matcher.localize, problem)
    assert est.pose.is_finite()


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "--benchmark-only"]))
