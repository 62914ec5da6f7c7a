"""Trajectory scores on hand-made trajectories: evo's APE/RPE (no alignment) and the operator's
view (tracked share, losses, recoveries, longest lost stretch)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.trajectory import episodes, errors, score_rows, score_track


def _line(n: int = 101, step: float = 0.1) -> np.ndarray:
    return np.column_stack([np.arange(n) * step, np.zeros(n), np.zeros(n)])


def test_perfect_track():
    t = _line()
    s = score_track(t.copy(), t, np.full(len(t), 0.003))
    assert (s.tracked, s.losses, s.recoveries, s.unrecovered, s.longest_lost_m) == (1.0, 0, 0, 0, 0.0)
    assert s.ape_rmse_m == pytest.approx(0.0, abs=1e-12) and s.rpe_trans_m_per_m == pytest.approx(0.0, abs=1e-12)
    assert s.cpu_ms_median == pytest.approx(3.0) and s.distance_m == pytest.approx(10.0)


def test_a_loss_that_recovers():
    t = _line()
    e = t.copy()
    e[30:40, 0] += 1.0          # lost for 10 scans (1 m off), back at scan 40
    e[50:55, 1] += 0.2          # degraded (not tracked) but not lost: 0.2 m < 0.5 m
    s = score_track(e, t)
    assert s.losses == 1 and s.recoveries == 1 and s.unrecovered == 0
    assert s.tracked == pytest.approx((101 - 15) / 101)
    assert s.longest_lost_m == pytest.approx(1.0)   # scans 30 → 40: 1 m of true travel
    # evo's APE: 10 scans with 1 m, 5 with 0.2 m, no alignment
    assert s.ape_rmse_m == pytest.approx(math.sqrt((10 * 1.0 + 5 * 0.04) / 101))
    assert s.ape_max_m == pytest.approx(1.0) and s.ape_mean_m == pytest.approx((10 + 1.0) / 101)


def test_a_loss_that_does_not_recover_and_a_lost_heading():
    t = _line()
    e = t.copy()
    e[80:, 2] += math.radians(15)   # heading off by 15° from scan 80 to the end: lost, never back
    s = score_track(e, t)
    assert (s.losses, s.recoveries, s.unrecovered) == (1, 0, 1)
    assert s.longest_lost_m == pytest.approx(2.0)   # scans 80 → 100
    assert s.ape_rot_max_deg == pytest.approx(15.0) and s.ape_rmse_m == pytest.approx(0.0, abs=1e-12)


def test_an_offset_is_not_aligned_away():
    """A constant 0.3 m offset stays 0.3 m (no alignment); RPE sees no relative error."""
    t = _line()
    e = t.copy()
    e[:, 1] += 0.3
    s = score_track(e, t)
    assert s.ape_rmse_m == pytest.approx(0.3) and s.tracked == 0.0 and s.losses == 0
    assert s.rpe_trans_m_per_m == pytest.approx(0.0, abs=1e-9)


def test_two_losses_recovery_needs_the_success_thresholds():
    d = np.array([0, 0.6, 0.3, 0.6, 0.05, 0.7, 0.7, 0.08, 0])
    o = np.zeros_like(d)
    # scan 1 lost; 2 is not tracked (0.3 m) nor lost; 3 lost again: the same stretch; 4 recovers
    assert episodes(d, o, Thresholds()) == [(1, 4), (5, 7)]


def test_rows_without_truth_are_left_out():
    t = _line(21)
    rows = [{"est_x": x, "est_y": y, "est_theta": th, "true_x": x, "true_y": y, "true_theta": th, "cpu_s": 0.001}
            for x, y, th in t]
    rows[5].update(true_x=None, true_y=None, true_theta=None)
    s = score_rows(rows)
    assert s.n_scans == 21 and s.n_truth == 20 and s.tracked == 1.0


def test_errors_wrap_angles():
    d, o = errors(np.array([[0, 0, math.pi - 0.01]]), np.array([[0, 0, -math.pi + 0.01]]))
    assert o[0] == pytest.approx(0.02)


def test_jumps_are_estimates_far_from_their_prediction():
    t = np.column_stack([np.arange(10.0) * 0.3, np.zeros(10), np.zeros(10)])
    e = t.copy()
    e[4, 0] += 2.5                         # one scan lands 2.5 m off, the next comes back
    pred = t.copy()
    pred[5] = e[4]                         # ... so it starts 2.5 m off and jumps back
    s = score_track(e, t, pred=pred)
    assert s.jumps == 2 and s.max_jump_m == pytest.approx(2.5)
    assert score_track(t, t, pred=t).jumps == 0 and np.isnan(score_track(t, t).max_jump_m)
