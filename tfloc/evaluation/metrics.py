"""Accuracy, success, failure-outcome and runtime metrics over a run's estimates (pure functions).

Input is the ``estimates.csv`` table as the store reads it (:meth:`tfloc.io.rundir.RunDir.results`:
numbers as numbers, text as text); errors there are in metres and radians, the metrics here are reported in cm, degrees, ms and percent.

Which rows count where (stated in every report):

* **rows with truth**: the true pose is known. They all count in the success rate and in the
  outcome shares; a scan without an answer (``failed``, ``timeout``, ``error:*``, and
  ``invalid:*``: the data poses no problem, e.g. the initial pose lies outside the map) counts as
  a failure with outcome ``no-answer``; invalid rows are counted apart (``n_invalid``), not as errors.
* **rows with an estimate**: status ``ok`` or ``failed`` with a finite pose, hence finite
  errors. Error and improvement statistics use only these; the others are *excluded* and
  counted in ``n_excluded``.
* **timed rows**: status ``ok`` or ``failed`` with a runtime (timeouts and errors have none).
  Runtimes are CPU time (``cpu_s``: the worker process's, all threads, during ``localize``);
  the wall time (``runtime_s``) is kept beside it, and their ratio shows contention. Runs made
  before ``cpu_s`` existed have no CPU time (``n_cpu`` = 0).

Intervals (:mod:`tfloc.evaluation.stats`): the success rate has a Wilson 95 % interval
(``success_lo_pct``, ``success_hi_pct``); the median distance error and the median CPU time
have percentile bootstrap 95 % intervals (``*_median_lo_*``, ``*_median_hi_*``).

Bins are left-closed, right-open: ``[0, 100)``, ``[100, 200)``, ``[200, 300)`` cm and
``[300, ∞)``; an initial offset of exactly 100 cm falls in ``100–200``. Angle bins likewise
``[0, 5)``, ``[5, 10)``, ``[10, 15)``, ``[15, ∞)`` degrees. Offsets are rounded to 1e-6 cm /
1e-6 ° before binning, so unit conversions cannot move a value across an edge.
"""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd

from tfloc.core.result import kind_of_status
from tfloc.core.rows.summary import METRICS
from tfloc.core.thresholds import Thresholds
from tfloc.datasets.protocol import ANGLE_BINS_DEG, DIST_BINS_M

from .outcome import (
    DIVERGED,
    NEAR,
    OUTCOMES,
    SUCCESS,
    UNSCORED,
    outcome,
    search_outcome,
)
from .stats import bootstrap_median, wilson

#: The protocol's offset bins (:mod:`tfloc.datasets.protocol`) as report bins, plus an open last bin.
DIST_EDGES_CM = (*(100.0 * lo for lo, _ in DIST_BINS_M), 100.0 * DIST_BINS_M[-1][1])
ANGLE_EDGES_DEG = (*(lo for lo, _ in ANGLE_BINS_DEG), ANGLE_BINS_DEG[-1][1])


def _labels(edges: tuple[float, ...]) -> tuple[str, ...]:
    return (*(f"{a:g}–{b:g}" for a, b in itertools.pairwise(edges)), f"≥{edges[-1]:g}")


DIST_BINS = _labels(DIST_EDGES_CM)
ANGLE_BINS = _labels(ANGLE_EDGES_DEG)
#: the metrics of a summary row, in column order (:class:`~tfloc.core.rows.summary.SummaryRow`)
METRIC_COLUMNS = METRICS


def _bin(values: pd.Series, edges: tuple[float, ...], labels: tuple[str, ...]) -> pd.Series:
    v = np.round(values.to_numpy(dtype=float), 6)
    idx = np.searchsorted(np.asarray(edges), v, side="right") - 1  # [lo, hi)
    ok = np.isfinite(v) & (v >= 0)
    out = np.where(ok, np.asarray(labels, dtype=object)[np.clip(idx, 0, len(labels) - 1)], None)
    return pd.Series(pd.Categorical(out, categories=list(labels), ordered=True), index=values.index)


def dist_bin(init_dist_err_m: pd.Series) -> pd.Series:
    """Initial distance offset bins (labels :data:`DIST_BINS`, cm) of metres; NaN → missing."""
    return _bin(init_dist_err_m.astype(float) * 100.0, DIST_EDGES_CM, DIST_BINS)


def angle_bin(init_orient_err_rad: pd.Series) -> pd.Series:
    """Initial angle offset bins (labels :data:`ANGLE_BINS`, degrees) of radians; NaN → missing."""
    deg = np.degrees(init_orient_err_rad.astype(float).abs())
    return _bin(deg, ANGLE_EDGES_DEG, ANGLE_BINS)


def has_truth(df: pd.DataFrame) -> pd.Series:
    """Rows whose true pose is known."""
    return df["true_x"].astype(float).notna()


def status_kinds(status: pd.Series) -> pd.Series:
    """The kind (``ok``, ``failed``, ``invalid``, ``timeout``, ``error``) of each row's status."""
    return status.astype(str).map(kind_of_status)


def tracked(df: pd.DataFrame, thr: Thresholds) -> np.ndarray:
    """Per row, whether its errors lie within the tracked thresholds (NaN errors: not tracked);
    the tracking tables' rule, one copy for every reader of rows."""
    d = df["dist_err_m"].to_numpy(float)
    o = df["orient_err_rad"].to_numpy(float)
    return np.asarray(thr.success(d, o), dtype=bool).reshape(-1)


def has_estimate(df: pd.DataFrame) -> pd.Series:
    """Rows with status ok/failed and finite errors (the rows of the error statistics)."""
    d, o = df["dist_err_m"].astype(float), df["orient_err_rad"].astype(float)
    return df["status"].isin(["ok", "failed"]) & np.isfinite(d) & np.isfinite(o)


def classify(df: pd.DataFrame, thr: Thresholds) -> pd.Series:
    """The outcome of each row under thresholds ``thr``: :func:`tfloc.evaluation.outcome.outcome`,
    the rule the worker applied, on the recorded errors and scores (missing without truth).
    A row that failed only under stricter thresholds than the run's has no recorded scores: it
    keeps a recorded failure outcome, else it is ``unscored``."""
    nan = pd.Series(np.nan, index=df.index)
    num = {c: df.get(c, nan).astype(float) for c in ("dist_err_m", "orient_err_rad", "score_est", "score_true")}
    recorded = df.get("outcome", pd.Series("", index=df.index)).fillna("").astype(str)
    out = outcome(df["status"] == "ok", num["dist_err_m"], num["orient_err_rad"], num["score_est"],
                  num["score_true"], thr, recorded.to_numpy(dtype=object))
    return pd.Series(np.where(has_truth(df), out, None), index=df.index, dtype=object)


def prepare(df: pd.DataFrame, thr: Thresholds) -> pd.DataFrame:
    """``df`` plus derived columns: bins, errors in cm/deg, improvements (%), outcome, runtime (ms)."""
    out = df.copy()
    num = {c: out[c].astype(float) for c in
           ("dist_err_m", "orient_err_rad", "init_dist_err_m", "init_orient_err_rad", "runtime_s")}
    num["cpu_s"] = out.get("cpu_s", pd.Series(np.nan, index=out.index)).astype(float)
    est = has_estimate(out)
    out["dist_bin"] = dist_bin(num["init_dist_err_m"])
    out["angle_bin"] = angle_bin(num["init_orient_err_rad"])
    out["truth"] = has_truth(out)
    out["estimate"] = est & out["truth"]
    out["dist_err_cm"] = (num["dist_err_m"] * 100.0).where(out["estimate"])
    out["orient_err_deg"] = np.degrees(num["orient_err_rad"]).where(out["estimate"])
    with np.errstate(divide="ignore", invalid="ignore"):
        di = 100.0 * (1.0 - num["dist_err_m"] / num["init_dist_err_m"])
        oi = 100.0 * (1.0 - num["orient_err_rad"] / num["init_orient_err_rad"])
    out["dist_impr_pct"] = di.where(out["estimate"] & (num["init_dist_err_m"] > 0))
    out["orient_impr_pct"] = oi.where(out["estimate"] & (num["init_orient_err_rad"] > 0))
    out["outcome_eval"] = classify(out, thr)
    out["search_eval"] = np.where(out["estimate"], search_outcome(
        num["dist_err_m"], num["orient_err_rad"], num["init_dist_err_m"], thr), None)
    timed = out["status"].isin(["ok", "failed"]) & num["runtime_s"].notna()
    out["runtime_ms"] = (num["runtime_s"] * 1000.0).where(timed)
    out["cpu_ms"] = (num["cpu_s"] * 1000.0).where(timed)
    return out


def _q(s: pd.Series, q: float) -> float:
    s = s.dropna()
    return float(np.percentile(s, q)) if len(s) else np.nan


def _stats(s: pd.Series, name: str, unit: str) -> dict[str, float]:
    s = s.dropna()
    return {f"{name}_mean_{unit}": s.mean() if len(s) else np.nan,
            f"{name}_std_{unit}": s.std(ddof=1) if len(s) > 1 else np.nan,
            f"{name}_median_{unit}": _q(s, 50), f"{name}_p90_{unit}": _q(s, 90),
            f"{name}_max_{unit}": s.max() if len(s) else np.nan}


def group_metrics(g: pd.DataFrame) -> dict[str, float]:
    """All metrics of one group of :func:`prepare`-d rows (see :data:`METRIC_COLUMNS`)."""
    n_truth = int(g["truth"].sum())
    kind = status_kinds(g["status"].fillna(""))
    m: dict[str, float] = {
        "n": len(g), "n_truth": n_truth, "n_est": int(g["estimate"].sum()),
        "n_excluded": n_truth - int(g["estimate"].sum()),
        "n_timeout": int((kind == "timeout").sum()), "n_error": int((kind == "error").sum()),
        "n_invalid": int((kind == "invalid").sum())}
    m.update(_stats(g["dist_err_cm"], "dist", "cm"))
    m.update(_stats(g["orient_err_deg"], "orient", "deg"))
    for k in ("dist", "orient"):
        s = g[f"{k}_impr_pct"].dropna()
        m[f"{k}_impr_mean_pct"] = s.mean() if len(s) else np.nan
        m[f"{k}_impr_median_pct"] = _q(s, 50)
        m[f"{k}_impr_min_pct"] = s.min() if len(s) else np.nan
    counts = g["outcome_eval"].value_counts()
    for o in (*OUTCOMES, UNSCORED):
        m[f"n_{o.replace('-', '_')}"] = int(counts.get(o, 0))
    for o in OUTCOMES:
        m[f"share_{o.replace('-', '_')}_pct"] = 100.0 * counts.get(o, 0) / n_truth if n_truth else np.nan
    m["success_rate_pct"] = m["share_success_pct"]
    searches = g["search_eval"].value_counts()
    m.update(n_near=int(searches.get(NEAR, 0)), n_diverged=int(searches.get(DIVERGED, 0)))
    lo, hi = wilson(int(counts.get(SUCCESS, 0)), n_truth)
    m.update(success_lo_pct=100.0 * lo, success_hi_pct=100.0 * hi)
    m["dist_median_lo_cm"], m["dist_median_hi_cm"] = bootstrap_median(g["dist_err_cm"])
    rt, cpu = g["runtime_ms"].dropna(), g["cpu_ms"].dropna()
    m.update(runtime_median_ms=_q(rt, 50), runtime_p95_ms=_q(rt, 95), n_timed=len(rt))
    lo, hi = bootstrap_median(cpu)
    both = g[["runtime_ms", "cpu_ms"]].dropna()
    both = both[both["cpu_ms"] > 0]
    m.update(cpu_median_ms=_q(cpu, 50), cpu_median_lo_ms=lo, cpu_median_hi_ms=hi, cpu_p95_ms=_q(cpu, 95),
             n_cpu=len(cpu), wall_per_cpu_median=_q(both["runtime_ms"] / both["cpu_ms"], 50))
    return m


def summarize(df: pd.DataFrame, by: list[str] | tuple[str, ...] = ("matcher",),
              thresholds: Thresholds | None = None) -> pd.DataFrame:
    """One row of metrics per group of ``by`` (``[]`` = one overall row).

    ``df`` is raw estimates or already :func:`prepare`-d (detected by the ``outcome_eval``
    column); ``thresholds`` defaults to 10 cm / 2°. Empty groups of categorical bins are omitted.
    """
    p = df if "outcome_eval" in df.columns else prepare(df, thresholds or Thresholds())
    by = list(by)
    if not by:
        return pd.DataFrame([group_metrics(p)], columns=list(METRIC_COLUMNS))
    rows = []
    for key, g in p.groupby(by, observed=True, sort=True, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        rows.append({**dict(zip(by, key, strict=True)), **group_metrics(g)})
    return pd.DataFrame(rows, columns=[*by, *METRIC_COLUMNS])
