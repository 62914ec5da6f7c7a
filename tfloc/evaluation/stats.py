"""Intervals and paired tests (pure functions): how sure a reported number and a difference are.

* :func:`wilson`: the Wilson score interval of a proportion (success rate). Unlike the normal
  approximation it stays inside [0, 1] and is not degenerate at 0/n or n/n.
* :func:`bootstrap_median`: the percentile bootstrap interval of a median (resampling the
  values with replacement, ``n_boot`` = 2000 resamples, seeded, so a report is reproducible).
  A resample's median depends only on one or two order statistics of the drawn indices, so
  those are drawn directly: the k-th smallest of n uniform variates is Beta(k, n − k + 1), the
  next one lies above it by (1 − U₍ₖ₎)·Beta(1, n − k), and ⌈n·U⌉ turns them into the order
  statistics of n indices drawn uniformly from 1..n. The same distribution as drawing n indices
  per resample, in O(1) per resample instead of O(n).
* :func:`mcnemar_exact`: McNemar's exact test for two matchers run on the same scans: under
  "equally good", each discordant scan (one succeeds, the other fails) is a fair coin, so the
  two-sided p-value is a binomial test of ``b`` successes in ``b + c`` trials at 1/2
  (``scipy.stats.binomtest``).
* :func:`paired_bootstrap_diff`: the percentile bootstrap interval of a success-rate difference
  on the same scans (resampling scans, i.e. pairs). Resampling pairs only matters through the
  counts of the three kinds of pair (a only, b only, neither or both), so the resampled counts
  are drawn from the multinomial they follow: the same distribution, at no cost in ``n``.
* :func:`ratio_of_medians`: the ratio of two medians measured on the same items (a matcher's
  CPU time over a reference matcher's, scan by scan) and its paired percentile bootstrap
  interval (resampling items).
* :func:`holm`: Holm's step-down adjustment of p-values for multiple comparisons (it controls
  the family-wise error rate; uniformly more powerful than Bonferroni).

Proportions are fractions in [0, 1] here; the metrics convert to percent.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy.stats import binomtest

Z95 = 1.959963984540054  # the standard normal's 97.5 % quantile
N_BOOT = 2000
SEED = 20261122


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval ``(lo, hi)`` of ``k`` successes in ``n`` trials; ``(nan, nan)`` if n = 0."""
    if n <= 0:
        return math.nan, math.nan
    p = k / n
    z2 = z * z
    denom = 1.0 + z2 / n
    centre = (p + z2 / (2 * n)) / denom
    half = z * math.sqrt(p * (1.0 - p) / n + z2 / (4 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def bootstrap_median(values: Sequence[float] | np.ndarray, n_boot: int = N_BOOT, seed: int = SEED,
                     level: float = 0.95) -> tuple[float, float]:
    """Percentile bootstrap interval ``(lo, hi)`` of the median of the finite ``values``
    (``(nan, nan)`` if there are none)."""
    v = np.asarray(values, dtype=float)
    v = np.sort(v[np.isfinite(v)])
    n = len(v)
    if n == 0:
        return math.nan, math.nan
    if n == 1 or v[0] == v[-1]:
        return float(v[0]), float(v[0])
    rng = np.random.default_rng(seed)
    k = (n + 1) // 2  # the median is the k-th smallest (n odd) or the mean of the k-th and next
    u = rng.beta(k, n - k + 1, size=n_boot)
    meds = v[np.minimum(np.ceil(n * u).astype(int), n) - 1]
    if n % 2 == 0:
        u2 = u + (1.0 - u) * rng.beta(1, n - k, size=n_boot)
        meds = 0.5 * (meds + v[np.minimum(np.ceil(n * u2).astype(int), n) - 1])
    a = (1.0 - level) / 2.0
    lo, hi = np.quantile(meds, [a, 1.0 - a])
    return float(lo), float(hi)


def mcnemar_exact(b: int, c: int) -> float:
    """Two-sided exact McNemar p-value for ``b`` scans where only the first of two matchers
    succeeded and ``c`` where only the second did (1.0 when there is no discordant scan)."""
    b, c = int(b), int(c)
    if b + c == 0:
        return 1.0
    return float(binomtest(b, b + c, 0.5, alternative="two-sided").pvalue)


def paired_bootstrap_diff(a: Sequence[bool] | np.ndarray, b: Sequence[bool] | np.ndarray,
                          n_boot: int = N_BOOT, seed: int = SEED,
                          level: float = 0.95) -> tuple[float, float, float]:
    """Success-rate difference ``mean(a) − mean(b)`` of paired outcomes (the same scans) and its
    percentile bootstrap interval: ``(diff, lo, hi)`` as fractions."""
    a, b = np.asarray(a, dtype=bool), np.asarray(b, dtype=bool)
    if a.shape != b.shape:
        raise ValueError(f"paired samples differ in length: {a.shape} vs {b.shape}")
    n = a.size
    if n == 0:
        return math.nan, math.nan, math.nan
    only_a, only_b = int(np.sum(a & ~b)), int(np.sum(~a & b))
    diff = (only_a - only_b) / n
    rng = np.random.default_rng(seed)
    counts = rng.multinomial(n, [only_a / n, only_b / n, (n - only_a - only_b) / n], size=n_boot)
    boot = (counts[:, 0] - counts[:, 1]) / n
    q = (1.0 - level) / 2.0
    lo, hi = np.quantile(boot, [q, 1.0 - q])
    return float(diff), float(lo), float(hi)


def ratio_of_medians(a: Sequence[float] | np.ndarray, b: Sequence[float] | np.ndarray,
                     n_boot: int = N_BOOT, seed: int = SEED, level: float = 0.95) -> tuple[float, float, float]:
    """``median(a) / median(b)`` of paired values (same items, same order) and its paired
    percentile bootstrap interval: ``(ratio, lo, hi)``."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape:
        raise ValueError(f"paired samples differ in length: {a.shape} vs {b.shape}")
    if a.size == 0:
        return math.nan, math.nan, math.nan
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = float(np.median(a) / np.median(b))
        idx = np.random.default_rng(seed).integers(0, a.size, size=(n_boot, a.size))
        boot = np.median(a[idx], axis=1) / np.median(b[idx], axis=1)
    q = (1.0 - level) / 2.0
    lo, hi = np.quantile(boot, [q, 1.0 - q])
    return ratio, float(lo), float(hi)


def holm(pvalues: Sequence[float] | np.ndarray) -> np.ndarray:
    """Holm-adjusted p-values (same order as given): reject where adjusted p < α keeps the
    family-wise error rate at α."""
    p = np.asarray(pvalues, dtype=float)
    m = p.size
    if m == 0:
        return p
    order = np.argsort(p, kind="stable")
    adj = np.minimum(1.0, np.maximum.accumulate(p[order] * (m - np.arange(m))))
    out = np.empty(m)
    out[order] = adj
    return out
