"""pytest-benchmark timings of one ``tf-plus`` ``localize`` on the test room, near and far.

Run: ``PYTHONPATH=$PWD pytest benchmarks/test_tfplus_timing.py --benchmark-only``
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import tfloc
from tfloc import LaserSpec, Pose, Problem

ROOT = Path(__file__).resolve().parents[1]
TRUE = Pose(2.5, 3.5, 0.3)


def _problem(offset: Pose) -> Problem:
    m = tfloc.load_map(ROOT / "data" / "maps" / "test-room.geojson")
    laser = LaserSpec.lms200()
    ranges = m.raycast(TRUE, laser) + np.random.default_rng(7).normal(0.0, 0.01, laser.n_beams)
    return Problem(m, laser, ranges, TRUE.compose(offset))


@pytest.mark.parametrize("offset", [Pose(0.3, 0.0, math.radians(5.0)), Pose(0.0, -2.5, math.radians(-12.0))],
                         ids=["0.3m-5deg", "2.5m-12deg"])
def test_tf_plus_localize_time(benchmark, offset: Pose) -> None:  # noqa: ANN001
    problem = _problem(offset)
    matcher = tfloc.get_matcher("tf-plus")
    matcher.localize(problem)  # compile the kernels and build the distance field outside the timing
    est = benchmark(matcher.localize, problem)
    assert est.pose.distance_to(TRUE) < 0.02


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "--benchmark-only"]))
