"""Search outcomes from poses alone: success, stalled near the truth, diverged, other."""

import math

import numpy as np

from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.outcome import search_outcome

THR = Thresholds()


def test_each_rule_and_their_order():
    deg = math.radians
    d = [0.05, 0.20, 0.20, 0.50, 1.50, 0.05, np.nan]
    o = [deg(1), deg(4), deg(8), deg(1), deg(1), deg(30), np.nan]
    d0 = [1.0, 1.0, 0.1, 1.0, 1.0, 0.01, 1.0]
    assert list(search_outcome(d, o, d0, THR)) == [
        "success", "near", "diverged", "other", "diverged", "diverged", "other"]
    # negative orientation errors count by magnitude
    assert search_outcome([0.05], [-deg(1)], [1.0], THR)[0] == "success"
    assert search_outcome(0.05, -deg(1), 1.0, THR) == "success"
