"""Metrics (tfloc.evaluation.metrics) against hand-computed examples."""

import math

import numpy as np
import pandas as pd
import pytest

from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.metrics import angle_bin, classify, dist_bin, prepare, summarize


def _row(d_m, o_deg, init_d_m, init_o_deg, status="ok", score_est=1.0, score_true=0.5,
         runtime_s=0.01, truth=True):
    return dict(dataset="d", scan_id="s", group="g", matcher="m", true_x=0.0 if truth else np.nan,
                status=status, dist_err_m=d_m, orient_err_rad=math.radians(o_deg),
                init_dist_err_m=init_d_m, init_orient_err_rad=math.radians(init_o_deg),
                runtime_s=runtime_s, score_est=score_est, score_true=score_true, outcome="")


@pytest.fixture
def four_rows():
    return pd.DataFrame([
        _row(0.05, 1.0, 1.0, 4.0, runtime_s=0.010),                                   # success
        _row(1.00, 0.0, 2.0, 8.0, score_est=1.0, score_true=0.5, runtime_s=0.030),    # local optimum
        _row(0.20, 3.0, 2.0, 12.0, score_est=0.1, score_true=0.5, runtime_s=0.020),   # ambiguous
        _row(np.nan, np.nan, 1.0, 0.0, status="timeout", score_est=np.nan, score_true=np.nan,
             runtime_s=np.nan),                                                      # no answer
    ])


def test_outcomes_hand_classified(four_rows):
    out = classify(four_rows, Thresholds())
    assert list(out) == ["success", "local-optimum", "ambiguous", "no-answer"]
    # a stricter distance threshold turns the 5 cm scan into a failure; its scores decide which
    strict = classify(four_rows, Thresholds(dist_m=0.04))
    assert strict.iloc[0] == "local-optimum"  # score_true 0.5 < score_est 1.0


def test_summary_hand_computed(four_rows):
    s = summarize(four_rows, by=[]).iloc[0]
    assert (s["n"], s["n_truth"], s["n_est"], s["n_excluded"], s["n_timeout"]) == (4, 4, 3, 1, 1)
    assert s["dist_mean_cm"] == pytest.approx((5 + 100 + 20) / 3)
    assert s["dist_median_cm"] == pytest.approx(20.0)
    assert s["dist_max_cm"] == pytest.approx(100.0)
    assert s["dist_p90_cm"] == pytest.approx(20 + 0.8 * 80)  # linear interpolation between 20 and 100
    assert s["orient_mean_deg"] == pytest.approx((1 + 0 + 3) / 3)
    # the paper's improvement 100·(1 − err/initial err), averaged over scans with an estimate
    assert s["dist_impr_mean_pct"] == pytest.approx((95 + 50 + 90) / 3)
    assert s["orient_impr_mean_pct"] == pytest.approx((75 + 100 + 75) / 3)
    assert s["success_rate_pct"] == pytest.approx(25.0)
    assert (s["n_success"], s["n_local_optimum"], s["n_ambiguous"], s["n_no_answer"]) == (1, 1, 1, 1)
    assert s["runtime_median_ms"] == pytest.approx(20.0)
    assert s["runtime_p95_ms"] == pytest.approx(20 + 0.9 * 10)
    assert s["n_timed"] == 3


def test_zero_initial_error_is_left_out_of_improvement():
    df = pd.DataFrame([_row(0.0, 1.0, 0.5, 0.0), _row(0.0, 1.0, 0.5, 4.0)])
    p = prepare(df, Thresholds())
    assert np.isnan(p["orient_impr_pct"].iloc[0]) and p["orient_impr_pct"].iloc[1] == pytest.approx(75.0)


def test_bins_left_closed():
    d = dist_bin(pd.Series([0.0, 0.999999, 1.0, 2.5, 3.0]))
    assert list(d.astype(str)) == ["0–100", "0–100", "100–200", "200–300", "≥300"]
    a = angle_bin(pd.Series(np.radians([-7.0, 5.0, 14.9, 15.0])))
    assert list(a.astype(str)) == ["5–10", "5–10", "10–15", "≥15"]
