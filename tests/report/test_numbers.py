"""The report's numbers you can trust: intervals, paired tests, CPU time and contention, failure
pictures drawn from a real (small) run."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from tests._estimates import frame, row, synthetic_run
from tests.harness.test_runner import cfg, make_dataset
from tfloc.cli.report import make_report as write_report
from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.metrics import prepare
from tfloc.evaluation.paired import paired_comparisons
from tfloc.evaluation.stats import mcnemar_exact, wilson
from tfloc.harness.config import MatcherSpec
from tfloc.harness.runner import run
from tfloc.io.estimates import read_estimates


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    path = synthetic_run(tmp_path_factory.mktemp("run") / "synthetic")
    files = write_report(path, with_figures=False)
    return path, files.report.read_text()


def test_summary_carries_wilson_and_bootstrap_bounds(synthetic):
    path, _ = synthetic
    s = pd.read_csv(path / "summary.csv")
    for _, r in s.iterrows():
        k = round(r.success_rate_pct * r.n_truth / 100.0)
        lo, hi = wilson(k, int(r.n_truth))
        assert r.success_lo_pct == pytest.approx(100 * lo, abs=1e-3)
        assert r.success_hi_pct == pytest.approx(100 * hi, abs=1e-3)
        if r.n_est > 1:
            assert r.dist_median_lo_cm <= r.dist_median_cm * (1 + 1e-5) <= r.dist_median_hi_cm * (1 + 2e-5)
        assert r.cpu_median_lo_ms <= r.cpu_median_ms * (1 + 1e-5) <= r.cpu_median_hi_ms * (1 + 2e-5)
        assert r.wall_per_cpu_median == pytest.approx(2.0)


def test_report_shows_intervals_paired_tests_and_contention(synthetic):
    path, md = synthetic
    assert "[95 % CI]" in md and "Wilson 95 % score intervals" in md
    assert "## Paired comparisons (same scans)" in md and "| `csm-corr` − `tf` |" in md
    assert "Holm-adjusted" in md
    assert "**Contention**: the median wall / CPU time per task is 2.00" in md
    assert "Load average (1 min) at the start of each session: 3.50; at the end: 4.25" in md
    assert "CPU median (ms) [95 % CI]" in md
    paired = pd.read_csv(path / "paired.csv")
    assert set(paired["dataset"]) >= {"office-pool", "all"}


def test_paired_comparison_counts_discordant_scans_by_hand():
    # a and b on 10 scans: both succeed on 0, only a on 1, only b on 9 → McNemar p = 22/1024
    rows = [row("a", 0.01 if i == 0 else 1.0, 0.1, scan_id=f"s{i}") for i in range(10)]
    rows += [row("b", 1.0 if i == 0 else 0.01, 0.1, scan_id=f"s{i}") for i in range(10)]
    t = paired_comparisons(prepare(frame(rows), Thresholds()))
    r = t.iloc[0]
    assert (r.a, r.b, r.n, r.only_a, r.only_b) == ("a", "b", 10, 1, 9)
    assert r.p_mcnemar == pytest.approx(22 / 1024) == pytest.approx(mcnemar_exact(1, 9))
    assert r.diff_pct == pytest.approx(-80.0) and r.diff_lo_pct < -80.0 < r.diff_hi_pct
    assert bool(r.significant)


def test_quiet_run_has_no_contention_warning(tmp_path):
    path = synthetic_run(tmp_path / "quiet", wall_per_cpu=1.0)
    md = write_report(path, with_figures=False).report.read_text()
    assert "no sign of contention" in md and "**Contention**" not in md


def test_run_without_cpu_times_says_so(tmp_path):
    frame([row("A", scan_id="a"), row("A", scan_id="b")]).drop(columns=["cpu_s"]).to_csv(
        tmp_path / "estimates.csv", index=False)
    (tmp_path / "run.json").write_text(json.dumps({}))
    md = write_report(tmp_path, with_figures=False).report.read_text()
    assert "No CPU times in this run" in md


def test_failure_pictures_of_a_real_run(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=6)
    out = run(cfg(ds, tmp_path / "run",
                  MatcherSpec.make("toy_matchers:TwoMinima", {"to_true": [0.2, -0.1]}, label="two-minima"),
                  MatcherSpec.make("toy_matchers:Stay", label="stay"), jobs=1, timeout_s=30.0), progress=False)
    df = read_estimates(out)
    assert (df["cpu_s"] >= 0).all() and df["cpu_s"].notna().all()
    sessions = json.loads((out / "run.json").read_text())["sessions"]
    assert len(sessions[-1]["loadavg_start"]) == 3 and len(sessions[-1]["loadavg_end"]) == 3
    md = write_report(out).report.read_text()
    pics = sorted((out / "figures" / "failures").rglob("*.png"))
    # each matcher failed all 6 scans with one outcome: the median-error scan and the worst
    assert {p.parent.name for p in pics} == {"two-minima", "stay"}
    assert len(pics) == 4
    for pic in pics:
        assert pic.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert f"({pic.relative_to(out).as_posix()})" in md
    assert "## Failure pictures" in md and "local-optimum: [" in md


def test_representatives_are_the_median_and_the_worst():
    from tfloc.report.failures import representatives

    g = pd.DataFrame({"dist_err_cm": [5.0, 1.0, np.nan, 3.0, 9.0], "init_dist_err_m": [1.0] * 5,
                      "dataset": ["d"] * 5, "scan_id": list("abcde")})
    assert list(representatives(g)["scan_id"]) == ["a", "c"]  # sorted b, d, a, e, c → index 2 and last


def test_resuming_a_run_made_before_cpu_s_keeps_its_columns(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=4)
    config = cfg(ds, tmp_path / "run", MatcherSpec.make("toy_matchers:Stay", label="stay"), jobs=1)
    out = run(config, progress=False)
    old = read_estimates(out).drop(columns=["cpu_s"]).iloc[:2]  # an older run, interrupted
    old.to_csv(out / "estimates.csv", index=False)
    run(config, progress=False)
    df = read_estimates(out)
    assert len(df) == 4 and "cpu_s" not in df.columns and (df["status"] == "ok").all()
    assert df["runtime_s"].notna().all()
