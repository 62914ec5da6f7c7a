"""A tracker's own confidence read as a lost-detector (tfloc.evaluation.selfassess)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from tfloc.core.thresholds import Thresholds
from tfloc.core.traits import Confidence
from tfloc.evaluation.selfassess import auc, caught, self_assessments, values

RESIDUAL = Confidence("score", False, "a residual")
FITNESS = Confidence("fitness", True, "a fitness")


def test_auc_perfect_reversed_and_chance() -> None:
    lost = np.r_[np.zeros(50, bool), np.ones(50, bool)]
    x = np.arange(100, dtype=float)
    assert auc(x, lost) == 1.0 and auc(-x, lost) == 0.0
    assert auc(np.ones(100), lost) == 0.5
    assert math.isnan(auc(x, np.zeros(100, bool)))


def test_caught_at_one_percent_false_alarms() -> None:
    lost = np.r_[np.zeros(1000, bool), np.ones(10, bool)]
    x = np.r_[np.linspace(0, 1, 1000), [5.0] * 6 + [0.5] * 4]
    assert caught(x, lost) == pytest.approx(0.6)


def test_values_turn_confidence_to_lostness_and_carry_the_last_value() -> None:
    info = pd.Series([json.dumps({"fitness": 0.9}), "{}", json.dumps({"fitness": 0.2})])
    assert values(info, FITNESS).tolist() == [-0.9, -0.9, -0.2]
    info = pd.Series(["{}", json.dumps({"score": 0.02})])
    v = values(info, RESIDUAL)
    assert math.isnan(v[0]) and v[1] == 0.02


def test_self_assessments_per_recording_and_pooled() -> None:
    """A residual that grows where the tracker is lost scores AUC 1; a tracker without a
    confidence is left out; scans without truth do not count."""
    rows = []
    for d in ("s1", "s2"):
        for k in range(40):
            lost = k >= 30
            rows.append({"dataset": d, "matcher": "t", "truth": k % 4 != 3,
                         "dist_err_m": 1.0 if lost else 0.01, "orient_err_rad": 0.0,
                         "info": json.dumps({"score": 0.5 if lost else 0.01})})
            rows.append({"dataset": d, "matcher": "u", "truth": True, "dist_err_m": 0.0,
                         "orient_err_rad": 0.0, "info": "{}"})
    p = pd.DataFrame(rows)
    out = self_assessments(p, ["s1", "s2"], Thresholds(), {"t": RESIDUAL, "u": None}.get)
    assert {(a.scope, a.matcher) for a in out} == {("s1", "t"), ("s2", "t"), ("all", "t")}
    pooled = next(a for a in out if a.scope == "all")
    assert pooled.auc == 1.0 and pooled.caught == 1.0 and pooled.scans == 60 and pooled.lost == 14
