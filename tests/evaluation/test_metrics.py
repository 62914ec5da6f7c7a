"""Metrics against hand-computed values: errors, improvement, success, outcomes, runtimes, bins."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from tests._estimates import frame, row
from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.metrics import angle_bin, classify, dist_bin, prepare, summarize
from tfloc.evaluation.summary import scenario_summary, summary_table


def errors_frame() -> pd.DataFrame:
    """Matcher A: 5 answered scans. Errors 1, 2, 3, 4, 50 cm and 0.5, 1, 1.5, 1.9, 10°; initial
    offsets 10, 20, 30, 40, 25 cm and 5, 5, 5, 5, 20°; runtimes 1, 2, 3, 4, 100 ms."""
    d = [0.01, 0.02, 0.03, 0.04, 0.50]
    o = [0.5, 1.0, 1.5, 1.9, 10.0]
    di = [0.10, 0.20, 0.30, 0.40, 0.25]
    oi = [5.0, 5.0, 5.0, 5.0, 20.0]
    rt = [0.001, 0.002, 0.003, 0.004, 0.100]
    rows = [row("A", d[i], o[i], di[i], oi[i], runtime_s=rt[i], scan_id=f"a{i}") for i in range(5)]
    rows[4].update(score_est=1.0, score_true=0.5)  # the truth scores better: local optimum
    return frame(rows)


def status_frame() -> pd.DataFrame:
    """Matcher B: a success, an ambiguous failure, a declined answer with a pose, a timeout, an error."""
    return frame([
        row("B", 0.02, 0.5, 1.0, 5.0, runtime_s=0.010, scan_id="b0"),
        row("B", 1.00, 20.0, 2.0, 10.0, runtime_s=0.020, scan_id="b1", score_est=0.2, score_true=0.9),
        row("B", 0.04, 1.0, 0.5, 2.0, status="failed", runtime_s=0.040, scan_id="b2"),
        row("B", None, None, 0.5, 2.0, status="timeout", runtime_s=None, scan_id="b3"),
        row("B", None, None, 0.5, 2.0, status="error:RuntimeError: boom", runtime_s=None, scan_id="b4"),
    ])


def test_error_statistics_by_hand():
    m = summarize(errors_frame(), ["matcher"]).iloc[0]
    assert m["n"] == 5 and m["n_est"] == 5 and m["n_excluded"] == 0
    assert m["dist_mean_cm"] == pytest.approx(12.0)            # (1+2+3+4+50)/5
    assert m["dist_median_cm"] == pytest.approx(3.0)
    assert m["dist_p90_cm"] == pytest.approx(31.6)             # 4 + 0.6·(50−4), linear interpolation
    assert m["dist_max_cm"] == pytest.approx(50.0)
    assert m["orient_mean_deg"] == pytest.approx((0.5 + 1 + 1.5 + 1.9 + 10) / 5)
    assert m["orient_median_deg"] == pytest.approx(1.5)
    assert m["orient_p90_deg"] == pytest.approx(1.9 + 0.6 * 8.1)
    assert m["orient_max_deg"] == pytest.approx(10.0)


def test_improvement_is_the_mean_of_per_scan_values_including_a_negative_one():
    m = summarize(errors_frame(), ["matcher"]).iloc[0]
    # per scan 90, 90, 90, 90 and 100·(1 − 50/25) = −100  →  mean 52
    assert m["dist_impr_mean_pct"] == pytest.approx(52.0)
    assert m["dist_impr_min_pct"] == pytest.approx(-100.0)
    assert m["dist_impr_median_pct"] == pytest.approx(90.0)
    # per scan 90, 80, 70, 62, 50  →  mean 70.4
    assert m["orient_impr_mean_pct"] == pytest.approx((90 + 80 + 70 + 62 + 50) / 5)


def test_success_rate_outcomes_and_runtime_percentiles():
    m = summarize(errors_frame(), ["matcher"]).iloc[0]
    assert m["success_rate_pct"] == pytest.approx(80.0)
    assert (m["n_success"], m["n_local_optimum"], m["n_ambiguous"], m["n_no_answer"]) == (4, 1, 0, 0)
    assert m["runtime_median_ms"] == pytest.approx(3.0)
    assert m["runtime_p95_ms"] == pytest.approx(4.0 + 0.8 * 96.0)


def test_no_answers_count_as_failures_and_are_excluded_from_error_statistics():
    m = summarize(status_frame(), ["matcher"]).iloc[0]
    assert (m["n"], m["n_truth"], m["n_est"], m["n_excluded"]) == (5, 5, 3, 2)
    assert (m["n_timeout"], m["n_error"]) == (1, 1)
    assert m["dist_mean_cm"] == pytest.approx((2 + 100 + 4) / 3)  # the declined scan's pose counts
    assert m["success_rate_pct"] == pytest.approx(20.0)
    assert (m["n_success"], m["n_local_optimum"], m["n_ambiguous"], m["n_no_answer"]) == (1, 0, 1, 3)
    assert m["share_no_answer_pct"] == pytest.approx(60.0)
    assert m["runtime_median_ms"] == pytest.approx(20.0)          # ok + failed rows: 10, 20, 40 ms
    assert m["runtime_p95_ms"] == pytest.approx(20.0 + 0.9 * 20.0)
    assert m["n_timed"] == 3


def test_summarize_groups_and_overall():
    df = pd.concat([errors_frame(), status_frame()], ignore_index=True)
    per = summarize(df, ["matcher"])
    assert list(per["matcher"]) == ["A", "B"]
    overall = summarize(df, [])
    assert len(overall) == 1 and overall.iloc[0]["n"] == 10
    assert overall.iloc[0]["success_rate_pct"] == pytest.approx(50.0)


def test_thresholds_are_inclusive_and_overridable():
    df = frame([row("A", 0.10, 1.0, scan_id="x"), row("A", 0.1001, 1.0, scan_id="y")])
    assert list(classify(df, Thresholds(0.10, 2.0))) == ["success", "unscored"]
    stricter = classify(errors_frame(), Thresholds(0.015, 2.0))
    # scans 2–4 succeeded in the run (no scores recorded), fail now: unscored; scan 5 keeps its scores
    assert list(stricter) == ["success", "unscored", "unscored", "unscored", "local-optimum"]
    m = summarize(errors_frame(), ["matcher"], thresholds=Thresholds(0.015, 2.0)).iloc[0]
    assert m["success_rate_pct"] == pytest.approx(20.0) and m["n_unscored"] == 3


def test_thresholds_from_run_json():
    assert Thresholds.from_run({"config": {"success": {"dist_m": 0.05, "orient_deg": 1.0}}}) == Thresholds(0.05, 1.0)
    assert Thresholds.from_run({}) == Thresholds(0.10, 2.0)


def test_distance_bins_are_left_closed():
    m = pd.Series([0.0, 0.999, 0.1 * 10, 1.0, 1.5, 2.0, 2.9999, 3.0, 4.2, np.nan, 0.99999999999])
    got = list(dist_bin(m).astype(object))
    assert got == ["0–100", "0–100", "100–200", "100–200", "100–200", "200–300", "200–300",
                   "≥300", "≥300", np.nan, "100–200"]


def test_angle_bins_are_left_closed_and_use_magnitude():
    r = pd.Series(np.radians([0.0, 4.999, 5.0, -7.0, 10.0, 14.99, 15.0, 40.0]))
    assert list(angle_bin(r).astype(object)) == ["0–5", "0–5", "5–10", "5–10", "10–15", "10–15", "≥15", "≥15"]


def test_bins_come_from_the_poses_not_the_group_labels():
    p = prepare(frame([row("A", init_dist_m=2.5, init_deg=12.0, group="d1-a1")]), Thresholds())
    assert p.loc[0, "dist_bin"] == "200–300" and p.loc[0, "angle_bin"] == "10–15"


def test_missing_truth_gives_no_scores():
    df = frame([row("A", 0.01, 0.5, truth=False), row("A", 0.02, 0.5, truth=False, scan_id="s1")])
    m = summarize(df, ["matcher"]).iloc[0]
    assert m["n"] == 2 and m["n_truth"] == 0 and m["n_est"] == 0
    assert math.isnan(m["success_rate_pct"]) and math.isnan(m["dist_mean_cm"])
    assert m["runtime_median_ms"] == pytest.approx(10.0)


def test_paper_scenarios_and_summary_groupings():
    rows = [row("A", 0.01, 0.5, 0.5, 2.0, dataset="detail-2", scan_id="d"),
            row("A", 0.02, 0.5, 1.0, 5.0, dataset="office-pool", scan_id="p0"),
            row("A", 0.03, 0.5, 2.5, 12.0, dataset="office-pool", scan_id="p1"),
            row("A", 0.04, 0.5, 0.2, 1.0, dataset="real-lab", scan_id="r")]
    p = prepare(frame(rows), Thresholds())
    paper = {"detail-2": ("I",), "office-pool": ("II", "III")}   # as their scenario.json declare
    sc = scenario_summary(p, paper)
    got = {(r.scenario, r.sample): r.n for r in sc.itertuples()}
    assert got == {("I", "detail-2"): 1, ("II", "5–10"): 1, ("II", "10–15"): 1,
                   ("III", "100–200"): 1, ("III", "200–300"): 1}
    assert scenario_summary(p, {}).empty        # by what they declare, not by their names
    t = summary_table(p, paper=paper)
    assert set(t["grouping"]) == {"scenario-I", "scenario-II", "scenario-III", "dataset",
                                  "dataset-dist_bin", "dataset-angle_bin", "overall"}
    overall = t[t["grouping"] == "overall"].iloc[0]
    assert overall["n"] == 4 and overall["dist_mean_cm"] == pytest.approx(2.5)
    assert t[(t["grouping"] == "scenario-II") & (t["bin"] == "10–15")].iloc[0]["dist_mean_cm"] == pytest.approx(3.0)
