"""Paired comparisons of matchers on the same scans: is a success-rate difference real?

Every matcher of a run answers the same scans, so two matchers are compared scan by scan:
``only_a`` scans where only ``a`` succeeded, ``only_b`` where only ``b`` did. The exact McNemar
test (:func:`tfloc.evaluation.stats.mcnemar_exact`) asks whether those discordant scans split
50/50; the paired bootstrap (:func:`tfloc.evaluation.stats.paired_bootstrap_diff`) gives a 95 %
interval of the difference. Within one table (one family: every pair of matchers on one set of
scans) the p-values are Holm-adjusted (:func:`tfloc.evaluation.stats.holm`), and a difference is
marked significant when its adjusted p-value is below ``ALPHA`` = 0.05.

Only scans with ground truth that both matchers have a row for are compared (a no-answer is a
failure, as in the success rate).
"""

from __future__ import annotations

import itertools

import pandas as pd

from .outcome import SUCCESS
from .stats import holm, mcnemar_exact, paired_bootstrap_diff

ALPHA = 0.05
PAIRED_COLUMNS = ["a", "b", "n", "success_a_pct", "success_b_pct", "only_a", "only_b",
                  "diff_pct", "diff_lo_pct", "diff_hi_pct", "p_mcnemar", "p_holm", "significant"]

#: A run of more than this many matcher labels is a parameter sweep: each label is paired with the
#: run's first only; its report draws the first label's failures only, its line figures a few
#: labels, its bar and box figures one row per label.
MANY_MATCHERS = 12


def success_matrix(p: pd.DataFrame) -> pd.DataFrame:
    """Success (bool, or missing) per scan ``(dataset, scan_id)`` × matcher of prepared rows."""
    t = p[p["truth"]]
    s = t.assign(_ok=(t["outcome_eval"] == SUCCESS).astype(float))
    return s.pivot_table(index=["dataset", "scan_id"], columns="matcher", values="_ok", aggfunc="first")


def paired_comparisons(p: pd.DataFrame, alpha: float = ALPHA, reference: str | None = None) -> pd.DataFrame:
    """One row per pair of matchers (``a`` before ``b`` alphabetically) on their common scans,
    columns :data:`PAIRED_COLUMNS` (percentages in percent, ``diff`` = a − b). With a
    ``reference`` (a parameter sweep of many labels), only the pairs (reference, other)."""
    m = success_matrix(p)
    rows = []
    pairs = (itertools.combinations(sorted(m.columns), 2) if reference is None else
             [(reference, b) for b in m.columns if b != reference and reference in m.columns])
    for a, b in pairs:
        both = m[[a, b]].dropna()
        if both.empty:
            continue
        sa, sb = both[a].to_numpy() > 0.5, both[b].to_numpy() > 0.5
        diff, lo, hi = paired_bootstrap_diff(sa, sb)
        only_a, only_b = int((sa & ~sb).sum()), int((~sa & sb).sum())
        rows.append({"a": a, "b": b, "n": len(both), "success_a_pct": 100.0 * sa.mean(),
                     "success_b_pct": 100.0 * sb.mean(), "only_a": only_a, "only_b": only_b,
                     "diff_pct": 100.0 * diff, "diff_lo_pct": 100.0 * lo, "diff_hi_pct": 100.0 * hi,
                     "p_mcnemar": mcnemar_exact(only_a, only_b)})
    out = pd.DataFrame(rows, columns=PAIRED_COLUMNS[:-2])
    out["p_holm"] = holm(out["p_mcnemar"].to_numpy())
    out["significant"] = out["p_holm"] < alpha
    return out


def paired_table(p: pd.DataFrame, scan_to_scan: set[str] = frozenset(),
                 reference: str | None = None) -> pd.DataFrame:
    """:func:`paired_comparisons` per dataset, and over all scan-to-map datasets pooled when the
    run has more than one (column ``dataset``; ``all`` for the pooled rows)."""
    t = p[p["truth"]]
    parts = [paired_comparisons(g, reference=reference).assign(dataset=d)
             for d, g in t.groupby("dataset", sort=False)]
    s2m = t[~t["dataset"].isin(scan_to_scan)]
    if s2m["dataset"].nunique() > 1:
        parts.append(paired_comparisons(s2m, reference=reference).assign(dataset="all"))
    parts = [x for x in parts if len(x)]
    if not parts:
        return pd.DataFrame(columns=["dataset", *PAIRED_COLUMNS])
    return pd.concat(parts, ignore_index=True)[["dataset", *PAIRED_COLUMNS]]
