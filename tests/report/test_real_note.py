"""The MIT CSAIL relations note: Kümmerle-style statistics and the failed-scan fallback."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _paths import SCEN

from tfloc.evaluation.relations import relation_stats
from tfloc.io.scenario import read_scans, read_scenario
from tfloc.report.relations_note import write_note

DATASET = SCEN / "real-csail-relations"


def test_relation_stats() -> None:
    s = relation_stats(np.array([0.0, 0.1, 0.2]), np.radians([1.0, -2.0, 3.0]), np.array([1, 1, 0]), np.array([0.001, 0.003, 0.002]))
    assert s["trans_mean_m"] == pytest.approx(0.1) and s["trans_max_m"] == pytest.approx(0.2)
    # the sample standard deviation, as in report.md (the note used ddof = 0 before: two rules)
    assert s["trans_std_m"] == pytest.approx(np.std([0, 0.1, 0.2], ddof=1)) == pytest.approx(0.1)
    assert s["trans_sq_mean_m2"] == pytest.approx((0.01 + 0.04) / 3)
    assert s["rot_mean_deg"] == pytest.approx(2.0) and s["rot_max_deg"] == pytest.approx(3.0)
    assert s["success"] == pytest.approx(2 / 3) and s["runtime_median_ms"] == pytest.approx(2.0)


def test_note_uses_estimates_and_falls_back_to_the_guess(tmp_path: Path) -> None:
    scans = read_scans(read_scenario(DATASET))
    ids = [s.scan_id for s in scans]
    rows = [{"dataset": "real-csail-relations", "scan_id": i, "matcher": "exact", "dist_err_m": 0.0, "orient_err_rad": 0.0, "runtime_s": 0.01,
             "status": "ok"} for i in ids]
    rows += [{"dataset": "real-csail-relations", "scan_id": i, "matcher": "broken", "dist_err_m": np.nan, "orient_err_rad": np.nan,
              "runtime_s": np.nan, "status": "error:boom"} for i in ids]
    pd.DataFrame(rows).to_csv(tmp_path / "estimates.csv", index=False)
    text = write_note(tmp_path, [DATASET]).read_text()
    line = next(s for s in text.splitlines() if s.startswith("| `exact`"))
    n = sum(not s.group.endswith("no-overlap") for s in scans)  # the first table: overlapping relations
    assert f"| {n} | 0.000 ± 0.000 | 0.00 |" in line and "| 100.0 [" in line
    odo = next(s for s in text.splitlines() if s.startswith("| odometry"))
    broken = next(s for s in text.splitlines() if s.startswith("| `broken`"))
    assert f"{n} not answered" in broken
    assert broken.split("|")[3:8] == odo.split("|")[3:8]  # fell back to the odometry guess
    assert "Not like for like" in text
    both = write_note(tmp_path, [DATASET, DATASET.parent / "real-csail-relations-perturbed"]).read_text()
    assert "## Protocol: odometry" in both and "## Protocol: perturbation" in both
    assert "### relations whose scans barely overlap (reported apart)" in both
