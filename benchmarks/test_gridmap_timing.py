"""Timing of GridMap's virtual sensor (pytest-benchmark; not a timed assertion).

Target from the design: ≤ 200 µs for 181 beams on a 1000 × 1000 grid. Run with
``pytest benchmarks/test_gridmap_timing.py --benchmark-only``; ``--benchmark-disable`` just runs
each once (CI smoke)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import tfloc
from tfloc.core.laser import LaserSpec
from tfloc.io.scenario import read_scans, read_scenario

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.fixture(scope="module")
def csail():
    """The MIT CSAIL corrected-log grid (1167 × 1735 cells at 5 cm) and its corrected poses."""
    sc = read_scenario(DATA / "scenarios" / "real-csail-scan-to-map")
    grid = tfloc.load_map(sc.map_path)
    poses = np.array([s.true.as_array() for s in read_scans(sc)])
    return grid, poses


@pytest.mark.parametrize("max_range", [10.0, 50.0])
def test_raycast_181_beams(benchmark, csail, max_range: float) -> None:
    grid, poses = csail
    laser = LaserSpec.from_degrees(max_range, 180, 1)
    grid.raycast(poses[0], laser)  # compile
    it = iter(np.resize(poses, (100000, 3)))
    r = benchmark(lambda: grid.raycast(next(it), laser))
    assert r.shape == (181,)


def test_raycast_batch_100_poses_361_beams(benchmark, csail) -> None:
    grid, poses = csail
    laser = LaserSpec.from_degrees(50, 180, 0.5)
    r = benchmark(grid.raycast, poses[:100], laser)
    assert r.shape == (100, 361)
