"""The verdict: each tracker's estimated tracked share on a recording, with its interval.

The share is the mean of the per-scan beliefs (:mod:`.belief`) over every scan of the recording
(truth or not: what a robot owner has). Its 95 % interval is a moving-block bootstrap over scans
(blocks of ``block_scans`` consecutive scans, seeded): neighbouring scans are not independent.
The interval covers the scans' sampling, not the beliefs' own errors, which the validation on
recordings with truth measures (:mod:`.agreement`).
"""

from __future__ import annotations

import math

import numpy as np


def block_bootstrap(values: np.ndarray, block: int, resamples: int, seed: int) -> tuple[float, float]:
    """The 95 % percentile interval of the mean of ``values`` (in order) under a moving-block
    bootstrap; NaN for fewer than two blocks."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    n = len(v)
    b = max(1, min(int(block), n))
    if n < 2 * b:
        return math.nan, math.nan
    starts = n - b + 1
    k = int(math.ceil(n / b))
    csum = np.concatenate(([0.0], np.cumsum(v)))
    sums = csum[b:] - csum[:-b]                      # every block's sum, by its start
    draw = np.random.default_rng(seed).integers(0, starts, size=(resamples, k))
    means = sums[draw].sum(axis=1) / (k * b)
    lo, hi = np.percentile(means, [2.5, 97.5])
    return float(lo), float(hi)


def share(beliefs: np.ndarray, block: int, resamples: int, seed: int) -> tuple[float, float, float]:
    """The believed-tracked share of one tracker's scans and its interval (fractions)."""
    b = np.asarray(beliefs, dtype=float)
    if not b.size:
        return math.nan, math.nan, math.nan
    lo, hi = block_bootstrap(b, block, resamples, seed)
    return float(b.mean()), lo, hi
