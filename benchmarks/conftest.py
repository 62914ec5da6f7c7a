"""Shared set-up of the pytest-benchmark suites: two cores, two threads, the bundled office map, an LMS200.

Timings follow DESIGN.md's protocol (process limited to 2 cores, thread pools of 2). The pinning
happens at import, before numpy/numba start their pools.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "2")
if hasattr(os, "sched_setaffinity"):
    _cpus = sorted(os.sched_getaffinity(0))
    os.sched_setaffinity(0, _cpus[:2])

from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from tfloc.core.laser import LaserSpec  # noqa: E402
from tfloc.core.pose import Pose  # noqa: E402
from tfloc.io.maps import load_map  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
from tfloc.maps.vector import VectorMap  # noqa: E402

try:  # limit BLAS/OpenMP pools that are already loaded, if threadpoolctl is available
    from threadpoolctl import threadpool_limits

    threadpool_limits(2)
except ImportError:
    pass


@pytest.fixture(scope="session")
def office() -> VectorMap:
    """The bundled office floor with rooms and corridors, no furniture (data/maps/office-1.geojson,
    81 segments): the map of Scenario I's first detail level."""
    m = load_map(ROOT / "data" / "maps" / "office-1.geojson")
    assert 70 <= len(m.segments) <= 110, len(m.segments)
    return m


@pytest.fixture(scope="session")
def lms200() -> LaserSpec:
    """The paper's SICK LMS200: 10 m, 180°, 1°, 181 beams."""
    return LaserSpec.lms200()


@pytest.fixture(scope="session")
def office_pose(office: VectorMap) -> Pose:
    """A pose in a room, facing the door and the corridor (sees many corners)."""
    pose = Pose(12.0, 3.5, 1.3)
    assert office.is_free(pose.xy[None, :], 0.2)[0]
    return pose


@pytest.fixture(scope="session")
def office_poses(office: VectorMap) -> np.ndarray:
    """100 fixed random free poses ``(100, 3)`` on the office floor."""
    rng = np.random.default_rng(7)
    xy = rng.uniform((0.3, 0.3), (19.7, 14.7), size=(1000, 2))
    xy = xy[office.is_free(xy, 0.2)][:100]
    assert len(xy) == 100
    return np.column_stack((xy, rng.uniform(-np.pi, np.pi, 100)))

