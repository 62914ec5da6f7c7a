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
:func:`headline_frame` is what ``report.md``, ``headline.csv``, the site and the README read.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

import numpy as np
import pandas as pd

from tfloc.core.thresholds import Thresholds

from .paired import ALPHA
from .stats import holm, mcnemar_exact, wilson
from .trajectory import pooled_share

#: a run's dataset modes (``tfloc.io.scenario``) → the measure its headline ranks by
MEASURES = {"single": "success", "scan-to-scan": "success", "sequence": "tracked", "global": "top-1"}
POOLED = "all"


@dataclass(frozen=True)
class HeadlineRow:
    """One matcher's line of a headline table (percentages in %, errors in cm, CPU in ms)."""

    mode: str
    scope: str
    rank: int
    matcher: str
    measure: str
    value_pct: float
    lo_pct: float
    hi_pct: float
    n: int
    error_cm: float
    error: str
    cpu_ms: float
    verdict: str
    next_matcher: str
    p_holm: float


HEADLINE_COLUMNS = [f.name for f in fields(HeadlineRow)]


def _hits(g: pd.DataFrame, mode: str, thr: Thresholds) -> pd.Series:
    """Per scan with truth: answered within the thresholds (a tracker's kept prediction counts as
    its estimate, as in the tracking tables; elsewhere the outcome rule decides)."""
    t = g[g["truth"]]
    if mode == "sequence":
        d = pd.to_numeric(t["dist_err_m"], errors="coerce")
        o = pd.to_numeric(t["orient_err_rad"], errors="coerce")
        return pd.Series(thr.success(d.to_numpy(float), o.to_numpy(float)), index=t.index)
    return t["outcome_eval"] == "success"


def _ape_cm(g: pd.DataFrame) -> float:
    d = pd.to_numeric(g.loc[g["truth"], "dist_err_m"], errors="coerce").dropna().to_numpy(float)
    return 100.0 * math.sqrt(float(np.mean(d ** 2))) if d.size else math.nan


def _median(s: pd.Series) -> float:
    v = pd.to_numeric(s, errors="coerce").dropna()
    return float(v.median()) if len(v) else math.nan


def _table(p: pd.DataFrame, mode: str, scope: str, thr: Thresholds) -> list[HeadlineRow]:
    """The ranked rows of one table (``p``: prepared rows of one mode, one scope)."""
    stats, hits = [], {}
    for m, g in p.groupby("matcher", sort=False):
        h = _hits(g, mode, thr)
        key = g.loc[h.index, "dataset"].astype(str) + "/" + g.loc[h.index, "scan_id"].astype(str)
        hits[m] = pd.Series(h.to_numpy(bool), index=key.to_numpy())
        k, n = int(h.sum()), int(len(h))
        if mode == "sequence" and g["dataset"].nunique() > 1:
            per = [(int(x.sum()), len(x)) for _, x in h.groupby(g.loc[h.index, "dataset"])]
            share, lo, hi = pooled_share([a for a, _ in per], [b for _, b in per])
        else:
            share = k / n if n else math.nan
            lo, hi = wilson(k, n)
        err = _ape_cm(g) if mode == "sequence" else _median(g.loc[g["truth"], "dist_err_cm"])
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
    for i, (m, v, lo, hi, n, err, cpu) in enumerate(stats):
        nxt = stats[i + 1][0] if i + 1 < len(stats) else ""
        p_adj = float(adj[i]) if i < len(adj) else math.nan
        verdict = "" if not nxt or math.isnan(p_adj) else "ahead" if p_adj < ALPHA else "tied"
        out.append(HeadlineRow(mode, scope, i + 1, m, MEASURES.get(mode, "success"), v, lo, hi, n, err,
                               "APE RMSE" if mode == "sequence" else "median error", cpu, verdict, nxt, p_adj))
    return out


def headline(p: pd.DataFrame, modes: dict[str, str], thr: Thresholds) -> list[HeadlineRow]:
    """Every headline table of prepared rows ``p`` (:func:`tfloc.evaluation.metrics.prepare`);
    ``modes``: dataset → mode. Datasets without truth are left out."""
    out: list[HeadlineRow] = []
    p = p[p["truth"]]
    for mode in MEASURES:
        names = [d for d in p["dataset"].unique() if modes.get(d, "single") == mode]
        if not names:
            continue
        if len(names) > 1:
            out += _table(p[p["dataset"].isin(names)], mode, POOLED, thr)
        for d in names:
            out += _table(p[p["dataset"] == d], mode, d, thr)
    return out


def headline_frame(rows: list[HeadlineRow]) -> pd.DataFrame:
    """``rows`` as a table in :data:`HEADLINE_COLUMNS` (``headline.csv``)."""
    return pd.DataFrame([asdict(r) for r in rows], columns=HEADLINE_COLUMNS)


def read_headline(path) -> list[HeadlineRow]:
    """The rows of a ``headline.csv`` (as :func:`headline_frame` wrote them)."""
    df = pd.read_csv(path, keep_default_na=False, na_values=[""])
    missing = [c for c in HEADLINE_COLUMNS if c not in df.columns]
    if missing:
        from tfloc.errors import ResultsError

        raise ResultsError(f"{path}: not a headline table (no column(s) {', '.join(missing)})")
    out = []
    for r in df.to_dict("records"):
        out.append(HeadlineRow(**{f.name: _cast(f.type, r[f.name]) for f in fields(HeadlineRow)}))
    return out


def _cast(kind: str, v):
    if kind == "int":
        return int(v)
    if kind == "float":
        return float("nan") if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else str(v)
