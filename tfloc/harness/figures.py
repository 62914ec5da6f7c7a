"""Report figures (PNG, matplotlib, Agg backend). Inputs are DataFrames from :mod:`.metrics`."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from .metrics import OUTCOMES, answered  # noqa: E402

_SC_COLORS = {"I": "tab:red", "II": "tab:blue", "III": "tab:green"}


def scenario_errors(summary: pd.DataFrame, path: Path) -> None:
    """Mean distance / orientation error per scenario group, one row of panels per matcher (Fig. 8)."""
    s = summary[summary["scenario"].isin(_SC_COLORS)]
    matchers = sorted(s["matcher"].unique())
    fig, axs = plt.subplots(max(1, len(matchers)), 2, figsize=(9, 2.6 * max(1, len(matchers))), squeeze=False)
    for r, m in enumerate(matchers):
        for c, (col, lab) in enumerate((("mean_dist_cm", "mean distance error (cm)"),
                                        ("mean_orient_deg", "mean orientation error (°)"))):
            ax = axs[r, c]
            for sc, color in _SC_COLORS.items():
                g = s[(s["matcher"] == m) & (s["scenario"] == sc)]
                ax.plot(np.arange(1, len(g) + 1), g[col], "o-", color=color, label=f"Scenario {sc}")
            ax.set_xticks([1, 2, 3])
            ax.set_xlabel("class")
            ax.set_ylabel(lab)
            ax.set_title(m)
            ax.grid(alpha=0.3)
    axs[0, 0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def convergence_basin(df: pd.DataFrame, path: Path) -> None:
    """Success rate against initial distance offset and initial angle offset, per matcher."""
    fig, axs = plt.subplots(1, 2, figsize=(10, 3.8))
    for col, scale, edges, ax, lab in (
            ("init_dist_err_m", 100.0, np.arange(0, 301, 25), axs[0], "initial distance offset (cm)"),
            ("init_orient_err_rad", 180.0 / np.pi, np.arange(0, 15.1, 1.25), axs[1], "initial angle offset (°)")):
        for m, g in df.groupby("matcher"):
            v = g[col].astype(float) * scale
            b = pd.cut(v, edges, include_lowest=True)
            rate = (g["outcome"] == "success").groupby(b, observed=False).mean()
            ax.plot(0.5 * (edges[1:] + edges[:-1]), rate.to_numpy(), "o-", label=m, ms=3)
        ax.set_xlabel(lab)
        ax.set_ylabel("success rate")
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def error_cdf(df: pd.DataFrame, path: Path) -> None:
    """Empirical CDF of distance and orientation errors per matcher (no-answer rows count as ∞)."""
    fig, axs = plt.subplots(1, 2, figsize=(10, 3.8))
    for m, g in df.groupby("matcher"):
        ok = answered(g)
        for ax, col, scale in ((axs[0], "dist_err_m", 100.0), (axs[1], "orient_err_rad", 180.0 / np.pi)):
            v = np.sort(np.where(ok, g[col].astype(float) * scale, np.inf))
            ax.step(v, np.arange(1, len(v) + 1) / len(v), where="post", label=m)
    for ax, lab in ((axs[0], "distance error (cm)"), (axs[1], "orientation error (°)")):
        ax.set_xscale("symlog", linthresh=1.0)
        ax.set_xlabel(lab)
        ax.set_ylabel("fraction of scans")
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def runtime(df: pd.DataFrame, path: Path) -> None:
    """Runtime of ``localize`` per scan (ms, log scale), one box per matcher."""
    groups = [(m, 1000.0 * g.loc[answered(g), "runtime_s"].astype(float)) for m, g in df.groupby("matcher")]
    fig, ax = plt.subplots(figsize=(1.6 * max(3, len(groups)), 3.8))
    ax.boxplot([v.to_numpy() if len(v) else [np.nan] for _, v in groups], showfliers=True)
    ax.set_xticks(np.arange(1, len(groups) + 1), [m for m, _ in groups])
    ax.set_yscale("log")
    ax.set_ylabel("runtime per scan (ms)")
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def outcomes(df: pd.DataFrame, path: Path) -> None:
    """Stacked bars: fraction of scans per outcome, per matcher."""
    tab = pd.crosstab(df["matcher"], df["outcome"], normalize="index").reindex(columns=list(OUTCOMES), fill_value=0.0)
    tab = tab.loc[:, (tab > 0).any()]
    fig, ax = plt.subplots(figsize=(1.6 * max(3, len(tab)), 3.8))
    bottom = np.zeros(len(tab))
    colors = {"success": "tab:green", "local-optimum": "tab:orange", "ambiguous": "tab:red",
              "no-answer": "tab:gray", "unscored": "tab:purple"}
    for o in tab.columns:
        ax.bar(tab.index, tab[o], bottom=bottom, label=o, color=colors[o])
        bottom += tab[o].to_numpy()
    ax.set_ylabel("fraction of scans")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
