"""``cv-corners`` on real 361-beam MIT CSAIL scans: accurate, and its work is bounded.

The first local relations of ``data/scenarios/real-csail-relations`` (scan at t2 matched against
the scan at t1 as a polyline map, from the odometry guess). Before the adaptive search these took
1.5–77 s of CPU each (5000 hypotheses scored in each of 5–6 steps, ~100 corners a scan); the checks
are a deterministic one (how much of the search ran) and a CPU-time bound ~30 times the measured
time, so that a loaded machine does not make them flaky.
"""

from __future__ import annotations

import csv
import math
import time

import numpy as np
import pytest
from _paths import SCEN
from tfloc.baselines._corner_match import search_hypotheses
from tfloc.baselines.cv_corners import CvCornersMatcher

import tfloc
from tfloc import LaserSpec, Pose, Problem, angdiff
from tfloc.maps.scanmap import polyline_map_from_scan

SCANS = SCEN / "real-csail-relations/scans.csv"
LASER = LaserSpec.from_degrees(50.0, 180.0, 0.5, -90.0)   # as its scenario.json
IDS = ("rel0001", "rel0002", "rel0003", "rel0004", "rel0005")


def _ranges(text: str) -> np.ndarray:
    r = np.array(text.split(), dtype=float)
    assert r.size == LASER.n_beams == 361
    return r


@pytest.fixture(scope="module")
def relations() -> list[tuple[str, Problem, Pose]]:
    out = []
    with SCANS.open(newline="") as fh:
        for row in csv.DictReader(fh):
            if row["scan_id"] in IDS:
                m = polyline_map_from_scan(_ranges(row["ref_ranges"]), LASER)
                init = Pose(*(float(row[f"init_{k}"]) for k in ("x", "y", "theta")))
                true = Pose(*(float(row[f"true_{k}"]) for k in ("x", "y", "theta")))
                out.append((row["scan_id"], Problem(m, LASER, _ranges(row["ranges"]), init), true))
    assert [sid for sid, _, _ in out] == list(IDS)
    return out


def test_real_scans_are_matched_accurately_with_bounded_work(relations) -> None:
    matcher = tfloc.get_matcher("cv-corners")
    cap = matcher.config.max_iterations * matcher.config.max_hypotheses
    matcher.localize(relations[0][1])                 # load the numba kernels before timing
    cpu = 0.0
    for sid, problem, true in relations:
        t0 = time.process_time()
        est = matcher.localize(problem)
        cpu += time.process_time() - t0
        assert est.info["status"] == "ok", sid
        assert est.pose.distance_to(true) <= 0.10, (sid, est)
        assert abs(angdiff(est.pose.theta, true.theta)) <= math.radians(2.0), (sid, est)
        # Deterministic: the adaptive stop, not the cap, ended the search (25000–30000 before).
        assert est.info["hypotheses_total"] <= cap / 3, (sid, est.info)
    # Measured 15–95 ms per scan (≈ 0.17 s for all five); before the adaptive search, 1.5–77 s each.
    assert cpu < 5.0, f"{cpu:.2f} s CPU for {len(relations)} real scans"


def test_adaptive_stop_draws_few_of_the_pairs_on_a_real_scan(relations) -> None:
    """On the scan with the most corners (rel0005, ~160 after filtering), the first step's search
    stops by confidence after drawing a small fraction of the real corner pairs."""
    matcher = CvCornersMatcher()
    c = matcher.config
    _, problem, _ = relations[-1]
    real = matcher._corners(problem.ranges, problem)
    virtual = matcher._corners(problem.map.raycast(problem.initial, problem.laser), problem)
    assert len(real) > 100
    found = search_hypotheses(real, virtual, c.length_tol, c.min_pair_length, math.radians(c.max_angle_deg),
                              c.max_shift, c.inlier_tol, c.confidence, c.max_hypotheses, c.seed)
    assert found is not None and found.inliers >= 30
    assert found.scored < c.max_hypotheses and found.drawn < found.pairs / 20, found
