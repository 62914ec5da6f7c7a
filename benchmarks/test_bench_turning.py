"""Turning function (Alg. 4) and matching (Sec. 4.3) timings on office-map scan polygons."""

from __future__ import annotations

import numpy as np
import pytest

from tfloc.core.pose import Pose
from tfloc.paper.shape import ShapeConfig, scan_corners, scan_polygon
from tfloc.paper.turning import match, turning_function


@pytest.fixture(scope="module")
def polygons(office, lms200, office_pose):
    """Scan polygons (S = 0.25 m, about 20-30 vertices) at the pose and 0.3 m / 3° off it."""
    cfg = ShapeConfig(spacing=0.25)
    off = Pose(office_pose.x + 0.3, office_pose.y - 0.2, office_pose.theta + np.radians(3))
    return [scan_polygon(scan_corners(office.raycast(p, lms200), lms200, cfg), cfg)
            for p in (office_pose, off)]


def test_turning_function(benchmark, polygons):
    turning_function(polygons[0])  # warm-up (JIT)
    tf = benchmark(turning_function, polygons[0])
    assert tf.n_edges >= 3


def test_match(benchmark, polygons):
    real, virtual = (turning_function(p) for p in polygons)
    match(real, virtual)  # warm-up (JIT)
    m = benchmark(match, real, virtual)
    assert m.distance >= 0.0 and 0 <= m.shift < virtual.n_edges
