"""Shared set-up of the pytest-benchmark suites: two cores, two threads, an office map, an LMS200.

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

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import shapely  # noqa: E402
from shapely.geometry import LineString, Polygon, box  # noqa: E402

from tfloc.core.laser import LaserSpec  # noqa: E402
from tfloc.core.pose import Pose  # noqa: E402
from tfloc.maps.vector import VectorMap  # noqa: E402

try:  # limit BLAS/OpenMP pools that are already loaded, if threadpoolctl is available
    from threadpoolctl import threadpool_limits

    threadpool_limits(2)
except ImportError:
    pass


def _wall_with_doors(x0: float, x1: float, y: float, doors: list[float], width: float = 0.9):
    """Horizontal wall from x0 to x1 at y, with door openings of ``width`` centred at ``doors``."""
    xs = [x0]
    for d in doors:
        xs += [d - width / 2, d + width / 2]
    xs.append(x1)
    return [LineString([(xs[i], y), (xs[i + 1], y)]) for i in range(0, len(xs), 2)]


def office_map() -> VectorMap:
    """A fixed 20 × 15 m office floor: eight rooms off a 3 m corridor, doors, furniture boxes.

    4 outline + 16 wall segments + 20 boxes × 4 = 100 segments (metres).
    """
    walls = []
    walls += _wall_with_doors(0.0, 20.0, 6.0, [2.5, 7.0, 12.5, 17.0])      # south corridor wall
    walls += _wall_with_doors(0.0, 20.0, 9.0, [3.0, 7.5, 13.0, 17.5])      # north corridor wall
    for x in (5.0, 10.0, 15.0):
        walls.append(LineString([(x, 0.0), (x, 6.0)]))
        walls.append(LineString([(x, 9.0), (x, 15.0)]))
    rng = np.random.default_rng(20261122)
    boxes = []
    rooms = [(rx, ylim) for rx in (0.0, 5.0, 10.0, 15.0) for ylim in ((0.4, 5.6), (9.4, 14.6))]
    attempt = 0
    while len(boxes) < 20:                      # rejection sampling, round-robin over the rooms
        room_x, (y_lo, y_hi) = rooms[attempt % len(rooms)]
        attempt += 1
        w, h = rng.uniform(0.5, 1.6), rng.uniform(0.4, 1.0)
        x = room_x + rng.uniform(0.4, 4.6 - w)
        y = rng.uniform(y_lo, y_hi - h)
        cand = box(x, y, x + w, y + h)
        if all(not cand.buffer(0.4).intersects(b) for b in boxes):
            boxes.append(cand)
    outline = Polygon([(0, 0), (20, 0), (20, 15), (0, 15)])
    return VectorMap(walls=tuple(walls), obstacles=tuple(boxes), outline=outline, name="office")


@pytest.fixture(scope="session")
def office() -> VectorMap:
    """The office map (about 100 segments)."""
    m = office_map()
    assert 90 <= len(m.segments) <= 110, len(m.segments)
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


__all__ = ["office_map", "shapely"]
