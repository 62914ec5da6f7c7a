"""Intervals and paired tests against hand-worked cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tfloc.evaluation.stats import (
    bootstrap_median,
    holm,
    mcnemar_exact,
    paired_bootstrap_diff,
    wilson,
)


def test_wilson_8_of_10_by_hand():
    # p = 0.8, n = 10, z² = 3.8415: centre = (0.8 + 0.19208) / 1.38415 = 0.71674,
    # half = 1.96 · sqrt(0.016 + 0.009604) / 1.38415 = 0.22658
    lo, hi = wilson(8, 10)
    assert lo == pytest.approx(0.4902, abs=1e-4) and hi == pytest.approx(0.9433, abs=1e-4)


def test_wilson_0_of_20_by_hand():
    # p = 0: lo = 0, hi = (z²/n) / (1 + z²/n) = 0.19208 / 1.19208 = 0.16113
    lo, hi = wilson(0, 20)
    assert lo == 0.0 and hi == pytest.approx(0.16113, abs=1e-4)


def test_wilson_is_symmetric_and_empty_is_nan():
    lo, hi = wilson(20, 20)
    assert hi == 1.0 and lo == pytest.approx(1 - wilson(0, 20)[1])
    assert all(math.isnan(x) for x in wilson(0, 0))


def test_mcnemar_exact_b1_c9_by_hand():
    # two-sided: 2 · P(X ≤ 1), X ~ Bin(10, 1/2) = 2 · (1 + 10) / 1024 = 22/1024
    assert mcnemar_exact(1, 9) == pytest.approx(22 / 1024, rel=1e-12)
    assert mcnemar_exact(9, 1) == pytest.approx(22 / 1024, rel=1e-12)


def test_mcnemar_without_discordant_pairs_is_one():
    assert mcnemar_exact(0, 0) == 1.0
    assert mcnemar_exact(3, 3) == pytest.approx(1.0)


def test_holm_by_hand():
    # sorted 0.01, 0.02, 0.04 times 3, 2, 1 = 0.03, 0.04, 0.04 (running max), back in input order
    assert holm([0.04, 0.01, 0.02]) == pytest.approx([0.04, 0.03, 0.04])
    assert holm([0.5, 0.9]) == pytest.approx([1.0, 1.0])


def test_paired_bootstrap_diff_is_seeded_and_brackets_the_difference():
    a = np.r_[np.ones(90, bool), np.zeros(10, bool)]
    b = np.r_[np.ones(70, bool), np.zeros(30, bool)]
    d, lo, hi = paired_bootstrap_diff(a, b)
    assert d == pytest.approx(0.2) and lo < 0.2 < hi and lo > 0.05 and hi < 0.35
    assert paired_bootstrap_diff(a, b) == (d, lo, hi)
    assert paired_bootstrap_diff(a, a) == (0.0, 0.0, 0.0)


def test_bootstrap_median_brackets_the_median_and_is_seeded():
    v = np.random.default_rng(1).exponential(10.0, 501)
    lo, hi = bootstrap_median(v)
    assert lo < np.median(v) < hi and hi - lo < 4.0
    assert bootstrap_median(v) == (lo, hi)
    assert bootstrap_median([3.0]) == (3.0, 3.0)
    assert all(math.isnan(x) for x in bootstrap_median([np.nan]))


@pytest.mark.parametrize("n", [7, 8, 40, 41])
def test_bootstrap_median_draws_the_same_distribution_as_resampling(n):
    v = np.sort(np.random.default_rng(n).exponential(1.0, n))
    rng = np.random.default_rng(0)
    brute = np.median(v[rng.integers(0, n, size=(40000, n))], axis=1)
    for level in (0.5, 0.8, 0.95):
        lo, hi = bootstrap_median(v, n_boot=40000, level=level)
        b_lo, b_hi = np.quantile(brute, [(1 - level) / 2, (1 + level) / 2])
        # quantiles of a discrete distribution: equal or one order statistic apart
        assert np.searchsorted(v, lo) == pytest.approx(np.searchsorted(v, b_lo), abs=1)
        assert np.searchsorted(v, hi) == pytest.approx(np.searchsorted(v, b_hi), abs=1)


def test_ratio_of_medians_is_paired_and_brackets_the_ratio():
    from tfloc.evaluation.stats import ratio_of_medians

    rng = np.random.default_rng(3)
    b = rng.lognormal(2.0, 0.8, 200)
    a = 3.0 * b  # exactly 3 × on every item: the paired interval collapses to 3
    assert ratio_of_medians(a, b) == pytest.approx((3.0, 3.0, 3.0))
    c = rng.lognormal(2.0, 0.8, 200)
    r, lo, hi = ratio_of_medians(c, b)
    assert lo < r < hi and lo > 0.5 and hi < 2.0
