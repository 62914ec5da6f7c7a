"""Accuracy regression guard: rerun a fixed-seed subset and compare with committed reference metrics.

Compared per matcher and per group (the nine distance × angle cells, and ``all``):

* success rate (%), higher is better: may drop by at most one scan of the group (100/n points);
* mean and median distance (cm) and orientation (°) errors, lower is better: may grow by at
  most 2 % of the reference plus 0.05 cm / 0.005°;
* local-optimum, ambiguous and no-answer counts, lower is better: may grow by at most 1.

The tracking guard (``benchmarks/regression-tracking.toml``, reference
``results/reference/tracking.csv``) compares, per matcher and sequence, the share of scans
tracked (may drop by one scan), the APE translation RMSE (may grow by 2 % + 0.05 cm) and the
unrecovered losses (may not grow), scored by :mod:`tfloc.evaluation.trajectory`.

Why these tolerances: every bundled matcher is deterministic (fixed seeds, no threads in the
numerics that affect results), and two runs on this machine gave identical summaries, so the
run-to-run spread is 0. The margins only absorb floating-point differences on another CPU (a
different SIMD width can round a sum differently, and a simplex search can then end one scan
elsewhere); they are far below any change worth making to a matcher.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from tfloc.core.thresholds import Thresholds

from .metrics import prepare, summarize

KEY = ("matcher", "group")


@dataclass(frozen=True)
class Rule:
    """How much worse ``metric`` may get: ``sign`` +1 if higher is better, −1 if lower is better."""

    metric: str
    sign: int
    rel: float = 0.0
    abs: float = 0.0
    per_scan: bool = False  # tolerance of one scan of the group, in percentage points

    def allowed(self, ref: float, n: int) -> float:
        """The worst value still accepted, given the reference value and the group size."""
        slack = (100.0 / n if self.per_scan and n else 0.0) + self.rel * abs(ref) + self.abs
        return ref - slack if self.sign > 0 else ref + slack


RULES = (
    Rule("success_rate_pct", +1, per_scan=True),
    Rule("dist_mean_cm", -1, rel=0.02, abs=0.05), Rule("dist_median_cm", -1, rel=0.02, abs=0.05),
    Rule("orient_mean_deg", -1, rel=0.02, abs=0.005), Rule("orient_median_deg", -1, rel=0.02, abs=0.005),
    Rule("n_local_optimum", -1, abs=1), Rule("n_ambiguous", -1, abs=1), Rule("n_no_answer", -1, abs=1),
)
GUARDED = ["n", *(r.metric for r in RULES)]
TRACK_RULES = (Rule("tracked_pct", +1, per_scan=True), Rule("ape_rmse_cm", -1, rel=0.02, abs=0.05),
               Rule("unrecovered", -1))
TRACK_GUARDED = ["n", *(r.metric for r in TRACK_RULES)]


def guard_summary(estimates: pd.DataFrame, thresholds: Thresholds) -> pd.DataFrame:
    """The guarded metrics per matcher and group, plus an ``all`` row per matcher."""
    p = prepare(estimates, thresholds)  # once: summarize takes prepared rows as they are
    per_group = summarize(p, by=["matcher", "group"], thresholds=thresholds)
    overall = summarize(p, by=["matcher"], thresholds=thresholds).assign(group="all")
    out = pd.concat([per_group, overall], ignore_index=True)[[*KEY, *GUARDED]]
    return out.sort_values(list(KEY), ignore_index=True)


def tracking_summary(estimates: pd.DataFrame, thresholds: Thresholds) -> pd.DataFrame:
    """The guarded tracking metrics per matcher and sequence (``group`` = the dataset)."""
    from .trajectory import score_rows

    rows = []
    for (ds, m), g in estimates.groupby(["dataset", "matcher"], sort=True):
        sc = score_rows(g, thresholds)
        rows.append({"matcher": m, "group": ds, "n": sc.n_truth, "tracked_pct": 100.0 * sc.tracked,
                     "ape_rmse_cm": 100.0 * sc.ape_rmse_m, "unrecovered": sc.unrecovered})
    return pd.DataFrame(rows, columns=[*KEY, *TRACK_GUARDED]).sort_values(list(KEY), ignore_index=True)


def compare(current: pd.DataFrame, reference: pd.DataFrame, rules: tuple[Rule, ...] = RULES) -> pd.DataFrame:
    """One row per (matcher, group, metric) with reference, current, allowed and ``worse``.

    A (matcher, group) in the reference but missing from the current run counts as worse.
    Matchers only in the current run are not compared (they have no reference yet).
    """
    ref = reference.set_index(list(KEY))
    cur = current.set_index(list(KEY))
    rows = []
    for key, r in ref.iterrows():
        if key[0] not in set(cur.index.get_level_values(0)):
            continue
        c = cur.loc[key] if key in cur.index else None
        for rule in rules:
            rv = float(r[rule.metric])
            cv = np.nan if c is None else float(c[rule.metric])
            allowed = rule.allowed(rv, int(r["n"]))
            if np.isnan(rv):
                worse = False
            elif np.isnan(cv):
                worse = True
            else:
                worse = cv < allowed - 1e-9 if rule.sign > 0 else cv > allowed + 1e-9
            rows.append({"matcher": key[0], "group": key[1], "metric": rule.metric,
                         "reference": rv, "current": cv, "allowed": allowed, "worse": worse})
    return pd.DataFrame(rows)


def format_table(diff: pd.DataFrame, only_worse: bool = True) -> str:
    """A readable fixed-width table of a comparison (by default only the regressions)."""
    d = diff[diff.worse] if only_worse else diff
    if d.empty:
        return "no regressions"
    d = d.assign(change=d.current - d.reference)
    return d[["matcher", "group", "metric", "reference", "current", "allowed", "change"]].to_string(
        index=False, float_format=lambda v: f"{v:.3f}")


def format_changes(old: pd.DataFrame, new: pd.DataFrame) -> str:
    """What ``--update`` changed: every guarded value that differs between old and new."""
    m = old.merge(new, on=list(KEY), how="outer", suffixes=("_old", "_new"), indicator=True)
    lines = []
    for _, r in m.iterrows():
        if r["_merge"] != "both":
            lines.append(f"{r.matcher:12s} {r.group:6s} {'added' if r['_merge'] == 'right_only' else 'removed'}")
            continue
        for k in (c for c in GUARDED + TRACK_GUARDED if f"{c}_old" in m):
            a, b = r[f"{k}_old"], r[f"{k}_new"]
            if not (np.isclose(a, b, equal_nan=True)):
                lines.append(f"{r.matcher:12s} {r.group:6s} {k:18s} {a:10.3f} -> {b:10.3f}")
    return "\n".join(lines) if lines else "no change"
