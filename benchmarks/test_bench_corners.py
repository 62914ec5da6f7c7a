"""ShortStraw timings (Algs. 1–3) on a 181-beam virtual scan of the office map."""

from __future__ import annotations

import pytest

from tfloc.paper.corners import corner_candidates, resample, shortstraw
from tfloc.paper.shape import ShapeConfig


@pytest.fixture(scope="module")
def scan_points(office, lms200, office_pose):
    return lms200.to_points(office.raycast(office_pose, lms200))


def test_to_points(benchmark, office, lms200, office_pose):
    """Eq. 4: ranges → sensor-frame points."""
    ranges = office.raycast(office_pose, lms200)
    lms200.to_points(ranges)  # warm-up (JIT)
    pts = benchmark(lms200.to_points, ranges)
    assert pts.shape[1] == 2


def test_shortstraw(benchmark, scan_points):
    """Resample + candidates + Is-Line merging at the paper's S = 1 m."""
    cfg = ShapeConfig()
    shortstraw(scan_points, cfg.spacing, cfg.window, cfg.straw_t, cfg.line_threshold)  # warm-up (JIT)
    c = benchmark(shortstraw, scan_points, cfg.spacing, cfg.window, cfg.straw_t, cfg.line_threshold)
    assert len(c) >= 3


def test_shortstraw_fine(benchmark, scan_points):
    """The same at S = 0.1 m (many more resampled points)."""
    shortstraw(scan_points, 0.1, 3, 0.99, 0.95)  # warm-up (JIT)
    c = benchmark(shortstraw, scan_points, 0.1, 3, 0.99, 0.95)
    assert len(c) >= 3


def test_corner_candidates(benchmark, scan_points):
    """Alg. 2 alone on the scan resampled at 0.1 m."""
    res = resample(scan_points, 0.1)
    corner_candidates(res, 3, 0.99)  # warm-up (JIT)
    cand = benchmark(corner_candidates, res, 3, 0.99)
    assert cand[0] == 0 and cand[-1] == len(res) - 1
