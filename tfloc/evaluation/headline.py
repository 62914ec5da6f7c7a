"""The headline of a run: every matcher ranked by its mode's success measure, best first, each
with its 95 % interval, its error, its CPU per scan and a paired test against the next.

One table per mode of the run's datasets (a single scan from a guess, scan-to-scan, tracking
along a sequence, global), for each dataset and, where the mode has several, pooled over them
(scope ``all``). The measure is the share of scans with truth answered within the thresholds:
*success* for a single scan or scan-to-scan, *tracked* along a sequence, *top-1* without a guess.
Its interval is Wilson's over scans, except a tracking share pooled over several sequences:
a percentile bootstrap over sequences (scans of one sequence are not independent). The error is
the median distance error (cm), for tracking the APE RMSE (cm). The verdict compares each matcher
with the next one down on the scans both answered: an exact McNemar test on success, p-values
Holm-adjusted within the table; ``ahead`` where adjusted p < 0.05, else ``tied``.

A sequence dataset without truth is ranked by the truth-free verdict instead (measure
*truth-free*: the share of scans each tracker is believed tracked, :mod:`tfloc.evaluation.
truthfree`, its per-scan beliefs taking the place of the truth in the interval and the paired
test; no error). Every tracking row also carries ``truth_free_score`` (the verdict on that scope,
made with the truth hidden: where there is truth, to compare) and ``self_auc`` (the tracker's own
confidence as a lost-detector, :mod:`tfloc.evaluation.selfassess`); NaN where not computed.
Its rows (:class:`~tfloc.core.rows.headline.HeadlineRow`) are computed once, by the derive step
(:mod:`tfloc.harness.derive`), into ``headline.csv``: what ``report.md``, the site and the README read.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from tfloc.core.modes import MODES, SEQUENCE, SINGLE, mode_of
from tfloc.core.modes import TRUTH_FREE as FREE_MODE
from tfloc.core.rows.headline import POOLED, HeadlineRow
from tfloc.core.thresholds import Thresholds

from .metrics import tracked
from .paired import ALPHA
from .stats import holm, mcnemar_exact, wilson
from .trajectory import pooled_share

#: the measure of a sequence dataset without truth
TRUTH_FREE = FREE_MODE.key

#: per (scope, matcher): a figure a headline row carries beside its measure
Extras = dict[tuple[str, str], float]
#: per (scope, matcher): the truth-free verdict's share and its interval (%), (score, lo, hi)
Verdicts = dict[tuple[str, str], tuple[float, float, float]]


def _hits(g: pd.DataFrame, mode: str, thr: Thresholds) -> pd.Series:
    """Per scan with truth: answered within the thresholds (a tracker's kept prediction counts as
    its estimate, as in the tracking tables; elsewhere the outcome rule decides). Truth-free: per
    scan, believed tracked."""
    if mode == TRUTH_FREE:
        return g["believed"].astype(bool)
    t = g[g["truth"]]
    if mode == SEQUENCE.key:
        return pd.Series(tracked(t, thr), index=t.index)
    return t["outcome_eval"] == "success"


def _ape_cm(g: pd.DataFrame) -> float:
    d = g.loc[g["truth"], "dist_err_m"].dropna().to_numpy(float)
    return 100.0 * math.sqrt(float(np.mean(d ** 2))) if d.size else math.nan


def _median(s: pd.Series) -> float:
    v = s.dropna()
    return float(v.median()) if len(v) else math.nan


def _table(p: pd.DataFrame, mode: str, scope: str, thr: Thresholds, free: Verdicts,
           auc: Extras) -> list[HeadlineRow]:
    """The ranked rows of one table (``p``: prepared rows of one mode, one scope; ``mode``
    :data:`TRUTH_FREE` for sequences without truth, ``p`` with a ``believed`` column)."""
    stats, hits = [], {}
    for m, g in p.groupby("matcher", sort=False):
        h = _hits(g, mode, thr)
        key = g.loc[h.index, "dataset"].astype(str) + "/" + g.loc[h.index, "scan_id"].astype(str)
        hits[m] = pd.Series(h.to_numpy(bool), index=key.to_numpy())
        k, n = int(h.sum()), int(len(h))
        if mode == TRUTH_FREE and scope != POOLED and (scope, m) in free:  # the verdict's own (block bootstrap)
            share, lo, hi = (x / 100 for x in free[(scope, m)])
        elif mode in (SEQUENCE.key, TRUTH_FREE) and g["dataset"].nunique() > 1:
            per = [(int(x.sum()), len(x)) for _, x in h.groupby(g.loc[h.index, "dataset"])]
            share, lo, hi = pooled_share([a for a, _ in per], [b for _, b in per])
        else:
            share = k / n if n else math.nan
            lo, hi = wilson(k, n)
        err = math.nan if mode == TRUTH_FREE else _ape_cm(g) if mode == SEQUENCE.key else \
            _median(g.loc[g["truth"], "dist_err_cm"])
        stats.append((m, 100 * share, 100 * lo, 100 * hi, n, err, _median(g["cpu_ms"])))
    stats.sort(key=lambda s: (-np.nan_to_num(s[1], nan=-1.0), np.nan_to_num(s[5], nan=np.inf),
                              np.nan_to_num(s[6], nan=np.inf), s[0]))
    pvals = []
    for (a, *_), (b, *_) in zip(stats, stats[1:], strict=False):
        both = pd.concat([hits[a], hits[b]], axis=1, join="inner")
        sa, sb = both.iloc[:, 0].to_numpy(bool), both.iloc[:, 1].to_numpy(bool)
        pvals.append(mcnemar_exact(int((sa & ~sb).sum()), int((~sa & sb).sum())) if len(both) else math.nan)
    adj = holm(np.array(pvals, dtype=float)) if pvals else np.array([])
    out = []
    named = mode_of(mode)
    measure, error = named.measure, named.error
    for i, (m, v, lo, hi, n, err, cpu) in enumerate(stats):
        nxt = stats[i + 1][0] if i + 1 < len(stats) else ""
        p_adj = float(adj[i]) if i < len(adj) else math.nan
        verdict = "" if not nxt or math.isnan(p_adj) else "ahead" if p_adj < ALPHA else "tied"
        out.append(HeadlineRow(SEQUENCE.key if mode == TRUTH_FREE else mode, scope, i + 1, m, measure, v, lo, hi,
                               n, err, error, cpu, verdict, nxt, p_adj,
                               v if mode == TRUTH_FREE else free.get((scope, m), (math.nan,))[0],
                               auc.get((scope, m), math.nan)))
    return out


def headline(p: pd.DataFrame, modes: dict[str, str], thr: Thresholds, beliefs: pd.DataFrame | None = None,
             free: Verdicts | None = None, auc: Extras | None = None) -> list[HeadlineRow]:
    """Every headline table of prepared rows ``p`` (:func:`tfloc.evaluation.metrics.prepare`);
    ``modes``: dataset → mode. A sequence dataset without truth is ranked by the truth-free
    verdict where ``beliefs`` (``dataset, scan_id, matcher, believed``) has it; other datasets
    without truth are left out. ``free``: the verdict (score, lo, hi) by (scope, matcher), the
    tracking rows' ``truth_free_score`` (and the truth-free tables' interval); ``auc``: their
    ``self_auc``."""
    free, auc = free or {}, auc or {}
    out: list[HeadlineRow] = []
    with_truth = set(p.loc[p["truth"], "dataset"])
    t = p[p["truth"]]
    for mode in MODES:
        names = [d for d in t["dataset"].unique() if modes.get(d, SINGLE.key) == mode]
        if not names:
            continue
        if len(names) > 1:
            out += _table(t[t["dataset"].isin(names)], mode, POOLED, thr, free, auc)
        for d in names:
            out += _table(t[t["dataset"] == d], mode, d, thr, free, auc)
    blind = [d for d in p["dataset"].unique() if modes.get(d) == SEQUENCE.key and d not in with_truth]
    if beliefs is not None and blind:
        b = p[p["dataset"].isin(blind)].merge(beliefs[["dataset", "scan_id", "matcher", "believed"]],
                                             on=["dataset", "scan_id", "matcher"], how="inner")
        names = [d for d in blind if d in set(b["dataset"])]
        if len(names) > 1:
            out += _table(b, TRUTH_FREE, POOLED, thr, free, auc)
        for d in names:
            out += _table(b[b["dataset"] == d], TRUTH_FREE, d, thr, free, auc)
    return out
