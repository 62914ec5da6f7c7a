"""Metrics of DESIGN.md as pure functions over an ``estimates.csv`` DataFrame.

Errors: distance ‖(x̂, ŷ) − (x, y)‖ (metres inside, cm in summaries) and orientation
|angdiff(θ̂, θ)| (radians inside, degrees in summaries). The paper's *improvement* is
100·(1 − err/initial_err) per scan; summaries give its mean over scans with an answer and a
non-zero initial error. Success: dist ≤ ``dist_m`` and orient ≤ ``orient_rad``. Outcome of a
scan: ``success``; else ``no-answer`` (error, timeout or no finite estimate); else
``local-optimum`` if the matcher's own score is lower at the true pose than at its answer;
else ``ambiguous`` (or ``unscored`` if a score could not be computed).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

OUTCOMES = ("success", "local-optimum", "ambiguous", "no-answer", "unscored")
ANGLE_BINS_DEG = (0.0, 5.0, 10.0, 15.0)
DIST_BINS_CM = (0.0, 100.0, 200.0, 300.0)


def pose_errors(true: np.ndarray, est: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance (m) and absolute orientation (rad, Eq. 6) errors of ``(N, 3)`` poses."""
    t, e = np.asarray(true, float).reshape(-1, 3), np.asarray(est, float).reshape(-1, 3)
    d = np.hypot(e[:, 0] - t[:, 0], e[:, 1] - t[:, 1])
    a = np.abs(np.arctan2(np.sin(e[:, 2] - t[:, 2]), np.cos(e[:, 2] - t[:, 2])))
    return d, a


def with_errors(df: pd.DataFrame) -> pd.DataFrame:
    """Copy of ``df`` with dist/orient errors of the estimate and of the initial pose (re)computed."""
    out = df.copy()
    true = out[["true_x", "true_y", "true_theta"]].to_numpy(float)
    out["dist_err_m"], out["orient_err_rad"] = pose_errors(true, out[["est_x", "est_y", "est_theta"]].to_numpy(float))
    out["init_dist_err_m"], out["init_orient_err_rad"] = pose_errors(
        true, out[["init_x", "init_y", "init_theta"]].to_numpy(float))
    return out


def answered(df: pd.DataFrame) -> pd.Series:
    """Rows with status ok and a finite estimate."""
    est = df[["est_x", "est_y", "est_theta"]].to_numpy(float)
    return (df["status"].astype(str) == "ok") & pd.Series(np.isfinite(est).all(axis=1), index=df.index)


def classify(df: pd.DataFrame, dist_m: float = 0.10, orient_rad: float = np.radians(2.0)) -> pd.Series:
    """The outcome of every row (see module docstring); needs the error and score columns."""
    ans = answered(df)
    ok = ans & (df["dist_err_m"] <= dist_m) & (df["orient_err_rad"] <= orient_rad)
    st, se = df["score_true"].astype(float), df["score_est"].astype(float)
    scored = np.isfinite(st) & np.isfinite(se)
    out = np.where(~ans, "no-answer", np.where(ok, "success", np.where(
        ~scored, "unscored", np.where(st < se, "local-optimum", "ambiguous"))))
    return pd.Series(out, index=df.index, name="outcome")


def improvement(err: pd.Series, init_err: pd.Series) -> pd.Series:
    """The paper's per-scan improvement 100·(1 − err/initial_err) (%); NaN where initial_err = 0."""
    init = init_err.astype(float).where(init_err.astype(float) > 0)
    return 100.0 * (1.0 - err.astype(float) / init)


def add_bins(df: pd.DataFrame) -> pd.DataFrame:
    """Copy with ``angle_bin`` (1–3: initial angle offset 0–5, 5–10, 10–15°) and ``dist_bin``
    (1–3: initial distance offset 0–100, 100–200, 200–300 cm), from the poses; 0 = outside."""
    out = df.copy()
    a = np.degrees(out["init_orient_err_rad"].to_numpy(float))
    d = 100.0 * out["init_dist_err_m"].to_numpy(float)
    for col, v, edges in (("angle_bin", a, ANGLE_BINS_DEG), ("dist_bin", d, DIST_BINS_CM)):
        b = np.searchsorted(np.asarray(edges), v, side="right")
        out[col] = np.where((v >= edges[0]) & (v <= edges[-1]), np.clip(b, 1, len(edges) - 1), 0)
    return out


def summarize_frame(g: pd.DataFrame) -> dict:
    """All metrics of one group of rows (units: cm, degrees, %, ms)."""
    ans = answered(g)
    a = g[ans]
    d_cm, o_deg = 100.0 * a["dist_err_m"].astype(float), np.degrees(a["orient_err_rad"].astype(float))
    rt = 1000.0 * g.loc[ans, "runtime_s"].astype(float)
    out = {"n": len(g), "n_answered": int(ans.sum())}
    for name, v in (("dist_cm", d_cm), ("orient_deg", o_deg)):
        out[f"mean_{name}"] = v.mean() if len(v) else np.nan
        out[f"median_{name}"] = v.median() if len(v) else np.nan
        out[f"p90_{name}"] = v.quantile(0.9) if len(v) else np.nan
        out[f"max_{name}"] = v.max() if len(v) else np.nan
    out["dist_improvement_pct"] = improvement(a["dist_err_m"], a["init_dist_err_m"]).mean()
    out["orient_improvement_pct"] = improvement(a["orient_err_rad"], a["init_orient_err_rad"]).mean()
    oc = g["outcome"].astype(str)
    out["success_rate"] = float((oc == "success").mean()) if len(g) else np.nan
    for o in OUTCOMES[1:]:
        out[f"n_{o}"] = int((oc == o).sum())
    out["runtime_median_ms"] = rt.median() if len(rt) else np.nan
    out["runtime_p95_ms"] = rt.quantile(0.95) if len(rt) else np.nan
    return out


def summarize(df: pd.DataFrame, by: list[str]) -> pd.DataFrame:
    """One row of :func:`summarize_frame` metrics per group of ``by``."""
    rows = [{**dict(zip(by, key if isinstance(key, tuple) else (key,), strict=True)), **summarize_frame(g)}
            for key, g in df.groupby(by, sort=True)]
    return pd.DataFrame(rows)


def scenario_rows(df: pd.DataFrame, pool: str = "office-pool", detail_prefix: str = "detail-") -> pd.DataFrame:
    """Long frame with ``scenario`` and ``group`` columns as the paper bins its scans:
    I = datasets named ``detail-*`` (group = dataset); II = the pool by initial angle offset bin;
    III = the pool by initial distance offset bin; ``dataset`` = each dataset; ``all`` = everything."""
    b = add_bins(df)
    parts = [b[b["dataset"].astype(str).str.startswith(detail_prefix)].assign(scenario="I", group=lambda x: x["dataset"])]
    p = b[b["dataset"] == pool]
    parts.append(p[p["angle_bin"] > 0].assign(scenario="II", group=lambda x: x["angle_bin"].astype(str)))
    parts.append(p[p["dist_bin"] > 0].assign(scenario="III", group=lambda x: x["dist_bin"].astype(str)))
    parts.append(b.assign(scenario="dataset", group=lambda x: x["dataset"]))
    parts.append(b.assign(scenario="all", group="all"))
    return pd.concat(parts, ignore_index=True)


def summary_table(df: pd.DataFrame, **kw) -> pd.DataFrame:
    """``summary.csv``: one row per matcher × scenario × group with every metric."""
    return summarize(scenario_rows(df, **kw), ["matcher", "scenario", "group"])
