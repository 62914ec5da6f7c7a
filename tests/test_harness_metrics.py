"""Metrics against hand-computed examples."""

import math

import numpy as np
import pandas as pd
import pytest

from tfloc.harness.metrics import add_bins, classify, improvement, pose_errors, summarize_frame, with_errors


def _row(true, est, init, status="ok", score_est=1.0, score_true=0.5, runtime=0.01):
    return dict(dataset="d", scan_id="s", group="g", matcher="m", true_x=true[0], true_y=true[1],
                true_theta=true[2], est_x=est[0], est_y=est[1], est_theta=est[2], init_x=init[0],
                init_y=init[1], init_theta=init[2], status=status, score_est=score_est,
                score_true=score_true, runtime_s=runtime)


def test_pose_errors_hand_computed():
    d, a = pose_errors(np.array([[0, 0, math.radians(179)]]), np.array([[3, 4, math.radians(-179)]]))
    assert d[0] == pytest.approx(5.0)
    assert a[0] == pytest.approx(math.radians(2.0))  # wraps across ±180°


def test_improvement_hand_computed():
    imp = improvement(pd.Series([0.1, 0.5, 0.2]), pd.Series([1.0, 0.5, 0.0]))
    assert imp[0] == pytest.approx(90.0) and imp[1] == pytest.approx(0.0) and np.isnan(imp[2])


def test_summary_and_outcomes_hand_computed():
    rows = [
        _row((0, 0, 0), (0.03, 0.04, math.radians(1)), (1, 0, math.radians(4)), runtime=0.010),  # success
        _row((0, 0, 0), (0.6, 0.8, 0.0), (2, 0, math.radians(8)), score_est=1.0, score_true=0.5,
             runtime=0.030),  # local optimum: 1 m off
        _row((0, 0, 0), (0.0, 0.2, math.radians(3)), (2, 0, math.radians(12)), score_est=0.1,
             score_true=0.5, runtime=0.020),  # ambiguous: 20 cm, 3°
        _row((0, 0, 0), (np.nan, np.nan, np.nan), (1, 0, 0.0), status="timeout"),
    ]
    df = with_errors(pd.DataFrame(rows))
    df["outcome"] = classify(df)
    assert list(df["outcome"]) == ["success", "local-optimum", "ambiguous", "no-answer"]
    s = summarize_frame(df)
    assert s["n"] == 4 and s["n_answered"] == 3
    assert s["mean_dist_cm"] == pytest.approx((5 + 100 + 20) / 3)
    assert s["median_dist_cm"] == pytest.approx(20.0)
    assert s["max_dist_cm"] == pytest.approx(100.0)
    assert s["p90_dist_cm"] == pytest.approx(20 + 0.8 * 80)  # linear interpolation, numpy default
    assert s["mean_orient_deg"] == pytest.approx((1 + 0 + 3) / 3)
    assert s["dist_improvement_pct"] == pytest.approx((95 + 50 + 90) / 3)
    assert s["orient_improvement_pct"] == pytest.approx((75 + 100 + 75) / 3)
    assert s["success_rate"] == pytest.approx(0.25)
    assert (s["n_local-optimum"], s["n_ambiguous"], s["n_no-answer"]) == (1, 1, 1)
    assert s["runtime_median_ms"] == pytest.approx(20.0)
    assert s["runtime_p95_ms"] == pytest.approx(20 + 0.9 * 10)


def test_bins_from_poses_not_labels():
    df = with_errors(pd.DataFrame([
        _row((0, 0, 0), (0, 0, 0), (0.5, 0, math.radians(7))),
        _row((0, 0, 0), (0, 0, 0), (0, 2.5, math.radians(-14))),
        _row((0, 0, 0), (0, 0, 0), (4, 0, math.radians(1)))]))
    b = add_bins(df)
    assert list(b["angle_bin"]) == [2, 3, 1]
    assert list(b["dist_bin"]) == [1, 3, 0]
