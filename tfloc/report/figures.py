"""The report's figures (matplotlib, Agg; no pyplot state): one function per PNG.

Each ``fig_*`` function takes prepared rows (:func:`tfloc.evaluation.metrics.prepare`) or metric
tables, writes one PNG and returns its path, or returns ``None`` when the run has nothing to
plot for it (e.g. no ground truth, no paper scenario datasets).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.outcome import OUTCOMES
from tfloc.evaluation.paired import MANY_MATCHERS
from tfloc.evaluation.paper import PAPER_TF

OUTCOME_COLOURS = {"success": "#2ca02c", "local-optimum": "#ff7f0e", "ambiguous": "#d62728",
                   "no-answer": "#7f7f7f"}
SCENARIO_TITLES = {"I": "Scenario I: detail level", "II": "Scenario II: initial angle offset",
                   "III": "Scenario III: initial distance offset"}
SCENARIO_X = {"I": "dataset", "II": "initial angle offset bin (°)", "III": "initial distance offset bin (cm)"}
DPI = 120
#: Metres between the map points drawn under a trajectory or a belief (the tracking figures).
MAP_SPACING_M = 0.05


def colours(matchers: list[str]) -> dict[str, tuple]:
    """One fixed colour per matcher (tab10 in sorted order), shared by all figures."""
    from matplotlib import colormaps

    cmap = colormaps["tab10"]
    return {m: cmap(i % 10) for i, m in enumerate(sorted(matchers))}


def _save(fig: Figure, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI, bbox_inches="tight")
    return path


def _nscans(g: pd.DataFrame) -> int:
    """Distinct scans (dataset, scan_id) among rows ``g``."""
    return len(g[["dataset", "scan_id"]].drop_duplicates())


def _legend_below(fig: Figure, handles: list, labels: list[str]) -> None:
    longest = max((len(x) for x in labels), default=0)  # long sweep labels: fewer columns
    ncol = min(len(labels), 6 if longest <= 24 else 3 if longest <= 48 else 2)
    fig.legend(handles, labels, loc="outside lower center", ncol=ncol, frameon=False)


def fig_scenarios(sc: pd.DataFrame, path: Path) -> Path | None:
    """Mean distance / orientation error per paper scenario sample, one line per matcher (Fig. 8)."""
    scen = [s for s in ("I", "II", "III") if (sc["scenario"] == s).any()]
    if not scen:
        return None
    col = colours(list(sc["matcher"].unique()))
    fig = Figure(figsize=(4.2 * len(scen), 7.0), layout="constrained")
    axes = fig.subplots(2, len(scen), squeeze=False)
    handles: dict[str, object] = {}
    for j, s in enumerate(scen):
        g = sc[sc["scenario"] == s]
        keys = [r.key for r in PAPER_TF if r.scenario == s]
        keys += [k for k in dict.fromkeys(g["sample"]) if k not in keys]
        x = {k: i for i, k in enumerate(keys)}
        for i, (metric, label) in enumerate((("dist_mean_cm", "mean distance error (cm)"),
                                             ("orient_mean_deg", "mean orientation error (°)"))):
            ax = axes[i][j]
            for m, gm in g.groupby("matcher", sort=True):
                gm = gm[gm[metric].notna()]
                (h,) = ax.plot([x[k] for k in gm["sample"]], gm[metric], "o-", color=col[m], lw=1.8)
                handles.setdefault(m, h)
            paper = [(x[r.key], r.dist_err_cm if i == 0 else r.orient_err_deg)
                     for r in PAPER_TF if r.scenario == s]
            (h,) = ax.plot(*zip(*paper, strict=True), "x--", color="black", lw=1.4)
            handles.setdefault("tf (paper, published)", h)
            ax.set_yscale("log")
            ax.set_xticks(range(len(keys)), keys)
            ax.set_xlim(-0.3, len(keys) - 0.7)
            ax.grid(True, which="both", alpha=0.3)
            ax.set_ylabel(label)
            if i == 0:
                ax.set_title(SCENARIO_TITLES[s])
            else:
                ax.set_xlabel(SCENARIO_X[s])
    _legend_below(fig, list(handles.values()), list(handles.keys()))
    fig.suptitle("Mean errors per scenario (log scale; dashed: the paper's published tf values)")
    return _save(fig, path)


def _families(p: pd.DataFrame, scan_to_scan: set[str], paper_datasets: Iterable[str] = ()) -> list[tuple[str, pd.DataFrame]]:
    t = p[p["truth"] & ~p["dataset"].isin(scan_to_scan)]
    paper = t[t["dataset"].isin(list(paper_datasets))]
    out = [("synthetic: " + ", ".join(sorted(paper["dataset"].unique())), paper)] if len(paper) else []
    for d in sorted(set(t["dataset"]) - set(paper["dataset"])):
        out.append((d, t[t["dataset"] == d]))
    return out


def _rate_curve(g: pd.DataFrame, values: pd.Series, width: float) -> tuple[np.ndarray, np.ndarray]:
    b = np.floor(values.to_numpy(dtype=float) / width)
    ok = (g["outcome_eval"] == "success").to_numpy()
    keys = np.unique(b[np.isfinite(b)])
    rate = np.array([100.0 * ok[b == k].mean() for k in keys])
    return (keys + 0.5) * width, rate


def fig_basin(p: pd.DataFrame, path: Path, scan_to_scan: set[str] = frozenset(),
              paper_datasets: Iterable[str] = ()) -> Path | None:
    """Convergence basin: success rate against initial distance and angle offset, per matcher
    (the datasets of the paper's scenarios pooled in one panel row)."""
    fams = _families(p, scan_to_scan, paper_datasets)
    if not fams:
        return None
    col = colours(list(p["matcher"].unique()))
    fig = Figure(figsize=(11, 3.6 * len(fams) + 0.6), layout="constrained")
    axes = fig.subplots(len(fams), 2, squeeze=False)
    handles: dict[str, object] = {}
    for i, (name, t) in enumerate(fams):
        dist_m = pd.to_numeric(t["init_dist_err_m"], errors="coerce")
        ang = np.degrees(pd.to_numeric(t["init_orient_err_rad"], errors="coerce"))
        aw = 1.0 if ang.max() <= 30 else 5.0
        for j, (vals, width, xl) in enumerate(((dist_m, 0.25, "initial distance offset (m), 0.25 m bins"),
                                               (ang, aw, f"initial angle offset (°), {aw:g}° bins"))):
            ax = axes[i][j]
            for m, gm in t.groupby("matcher", sort=True):
                x, y = _rate_curve(gm, vals[gm.index], width)
                (h,) = ax.plot(x, y, "o-", ms=3.5, color=col[m], lw=1.6)
                handles.setdefault(m, h)
            ax.set_ylim(-3, 103)
            ax.set_xlim(left=0)
            ax.grid(True, alpha=0.3)
            ax.set_xlabel(xl)
            ax.set_ylabel("success rate (%)")
            ax.set_title(f"{name} ({_nscans(t)} scans)", fontsize=10)
    _legend_below(fig, list(handles.values()), list(handles.keys()))
    fig.suptitle("Convergence basin: success rate against initial offset")
    return _save(fig, path)


def fig_cdf(p: pd.DataFrame, path: Path, thr: Thresholds) -> Path | None:
    """Cumulative distribution of distance and orientation errors per matcher (log x)."""
    t = p[p["truth"]]
    if t.empty or not t["estimate"].any():
        return None
    col = colours(list(p["matcher"].unique()))
    fig = Figure(figsize=(11, 4.4), layout="constrained")
    axes = fig.subplots(1, 2)
    specs = (("dist_err_cm", "distance error (cm)", 1e-3, thr.dist_m * 100.0),
             ("orient_err_deg", "orientation error (°)", 1e-4, thr.orient_deg))
    handles: dict[str, object] = {}
    for ax, (c, xl, floor, limit) in zip(axes, specs, strict=True):
        for m, g in t.groupby("matcher", sort=True):
            v = np.sort(np.maximum(g[c].dropna().to_numpy(), floor))
            if len(v) == 0:
                continue
            y = np.arange(1, len(v) + 1) / len(g)  # over all scans with truth: no-answers never arrive
            (h,) = ax.step(np.r_[floor, v], np.r_[0.0, y], where="post", color=col[m], lw=1.6)
            handles.setdefault(m, h)
        ax.axvline(limit, color="black", ls=":", lw=1)
        ax.set_xscale("log")
        ax.set_ylim(0, 1.02)
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlabel(xl + f"; dotted: success threshold {limit:g}")
        ax.set_ylabel("fraction of scans with error ≤ x")
    _legend_below(fig, list(handles.values()), list(handles.keys()))
    fig.suptitle(f"Error CDF over all scans with ground truth ({_nscans(t)} scans; "
                 f"values < {specs[0][2]:g} cm / {specs[1][2]:g}° drawn at that floor)")
    return _save(fig, path)


def fig_runtime(p: pd.DataFrame, path: Path) -> Path | None:
    """CPU time per scan (ms, log scale), one box per matcher, fastest first (wall time for runs
    without CPU time)."""
    metric = "cpu_ms" if "cpu_ms" in p and p["cpu_ms"].notna().any() else "runtime_ms"
    kind = "CPU time" if metric == "cpu_ms" else "wall time (this run has no CPU times)"
    t = p[p[metric].notna()]
    if t.empty:
        return None
    medians = t.groupby("matcher")[metric].median()
    matchers = sorted(medians.index, key=lambda m: (medians[m], m))  # fastest first
    col = colours(list(p["matcher"].unique()))
    wide = len(matchers) > MANY_MATCHERS  # a sweep: one row per label, names on the y axis
    size = (9.0, 0.25 * len(matchers) + 1.5) if wide else (max(5.0, 1.3 * len(matchers) + 2), 4.4)
    fig = Figure(figsize=size, layout="constrained")
    ax = fig.subplots()
    data = [np.maximum(t.loc[t["matcher"] == m, metric].to_numpy(), 1e-3) for m in matchers]
    bp = ax.boxplot(data, positions=range(len(matchers)), whis=(5, 95), showfliers=True, patch_artist=True,
                    orientation="horizontal" if wide else "vertical", medianprops={"color": "black"},
                    flierprops={"markersize": 2.5, "alpha": 0.5})
    for patch, m in zip(bp["boxes"], matchers, strict=True):
        patch.set_facecolor(col[m])
        patch.set_alpha(0.6)
    label = f"{kind.split(' (')[0]} per scan (ms)"
    if wide:
        ax.set_yticks(range(len(matchers)), matchers, fontsize=7)
        ax.invert_yaxis()
        ax.set_xscale("log")
        ax.grid(True, which="both", axis="x", alpha=0.3)
        ax.set_xlabel(label)
    else:
        ax.set_xticks(range(len(matchers)), matchers)
        ax.set_yscale("log")
        ax.grid(True, which="both", axis="y", alpha=0.3)
        ax.set_ylabel(label)
        ax.set_xlabel("matcher")
    ax.set_title(f"{kind[0].upper() + kind[1:]} per scan (box: quartiles, whiskers: p5–p95)")
    return _save(fig, path)


def fig_outcomes(p: pd.DataFrame, path: Path, scan_to_scan: set[str] = frozenset()) -> Path | None:
    """Outcome shares per matcher, most successful first: overall, and per initial distance bin
    (scan-to-map datasets)."""
    t = p[p["truth"]]
    if t.empty:
        return None
    panels = [("all datasets", t)]
    s2m = t[~t["dataset"].isin(scan_to_scan)]
    for b in s2m["dist_bin"].cat.categories:
        g = s2m[s2m["dist_bin"] == b]
        if len(g):
            panels.append((f"initial offset {b} cm", g))
    share = (t["outcome_eval"] == "success").groupby(t["matcher"]).mean()
    matchers = sorted(share.index, key=lambda m: (-share[m], m))  # most successful first
    wide = len(matchers) > MANY_MATCHERS  # a sweep: horizontal bars, one row per label
    size = ((3.0 * len(panels) + 5.0, 0.22 * len(matchers) + 2.0) if wide
            else (max(8.0, 0.55 * len(matchers) * len(panels) + 2), 4.6))
    fig = Figure(figsize=size, layout="constrained")
    axes = fig.subplots(1, len(panels), sharey=True, squeeze=False)[0]
    pos = np.arange(len(matchers))
    for ax, (title, g) in zip(axes, panels, strict=True):
        bottom = np.zeros(len(matchers))
        for o in OUTCOMES:
            share = np.array([100.0 * (g.loc[g["matcher"] == m, "outcome_eval"] == o).mean()
                              if (g["matcher"] == m).any() else 0.0 for m in matchers])
            if wide:
                ax.barh(pos, share, left=bottom, color=OUTCOME_COLOURS[o], label=o, edgecolor="white", lw=0.5)
            else:
                ax.bar(pos, share, bottom=bottom, color=OUTCOME_COLOURS[o], label=o, edgecolor="white", lw=0.5)
            bottom += share
        ax.set_title(f"{title}\n(n={_nscans(g)} scans)", fontsize=10)
        if wide:
            ax.set_xlim(0, 100)
            ax.grid(True, axis="x", alpha=0.3)
            ax.set_xlabel("share of scans (%)")
        else:
            ax.set_xticks(pos, matchers, rotation=45, ha="right")
            ax.set_ylim(0, 100)
            ax.grid(True, axis="y", alpha=0.3)
    if wide:
        axes[0].set_yticks(pos, matchers, fontsize=7)
        axes[0].invert_yaxis()
    else:
        axes[0].set_ylabel("share of scans (%)")
    h, lab = axes[0].get_legend_handles_labels()
    _legend_below(fig, h, lab)
    fig.suptitle("Outcomes per matcher (success / local-optimum / ambiguous / no-answer)")
    return _save(fig, path)
