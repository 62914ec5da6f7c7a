"""Virtual sensor timings: :meth:`VectorMap.raycast` on the ~100-segment office map, LMS200."""

from __future__ import annotations

import numpy as np


def test_raycast_one_pose(benchmark, office, lms200, office_pose):
    """One virtual scan (181 beams) from one pose; target ≤ 50 µs median."""
    office.raycast(office_pose, lms200)  # warm-up (JIT)
    r = benchmark(office.raycast, office_pose, lms200)
    assert r.shape == (lms200.n_beams,) and np.isfinite(r).sum() > 100


def test_raycast_100_poses(benchmark, office, lms200, office_poses):
    """A batch of 100 poses in one call."""
    office.raycast(office_poses, lms200)  # warm-up (JIT)
    r = benchmark(office.raycast, office_poses, lms200)
    assert r.shape == (100, lms200.n_beams) and np.isfinite(r).mean() > 0.5
