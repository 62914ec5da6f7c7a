"""The "robustness" section drawn: success per matcher on every map style and every changed
world (``robustness.csv`` and the paired changes, :mod:`tfloc.evaluation.robustness`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from tfloc.evaluation.robustness import style_key
from tfloc.evaluation.stats import wilson

from .mdtable import table


def _cell(r: pd.Series | None) -> str:
    if r is None:
        return "—"
    return f"{r['rate']:.1f}% [{r['lo']:.0f}–{r['hi']:.0f}]"


def robustness_table(cells: pd.DataFrame, log: str | None = None) -> str:
    """Markdown: rows = matchers (by mean success, best first), columns = styles; each cell
    success % [Wilson 95 %]. ``log`` = one log's columns; ``None`` pools every log of a style."""
    c = cells if log is None else cells[cells["log"] == log]
    if log is None:
        c = (c.groupby(["matcher", "style"], sort=False)[["n", "k"]].sum().reset_index())
        c["rate"] = 100.0 * c["k"] / c["n"]
        iv = [wilson(int(k), int(n)) for k, n in zip(c["k"], c["n"], strict=True)]
        c["lo"], c["hi"] = [100.0 * a for a, _ in iv], [100.0 * b for _, b in iv]
    styles = sorted(set(c["style"]), key=style_key)
    order = c.groupby("matcher")["rate"].mean().sort_values(ascending=False).index
    idx = {(r["matcher"], r["style"]): r for _, r in c.iterrows()}
    ns = {s: "/".join(sorted({str(int(v)) for v in c[c["style"] == s]["n"]})) for s in styles}
    headers = ["matcher"] + [f"{s} (n={ns[s]})" for s in styles]
    rows = [[m] + [_cell(idx.get((m, s))) for s in styles] for m in order]
    return table(headers, rows)


def changes_table(changes: pd.DataFrame, log: str) -> str:
    """Markdown: per matcher, the paired change of success (points) of every style of ``log``
    against its reference, with scans lost / gained."""
    c = changes[changes["log"] == log]
    styles = sorted(set(c["style"]), key=style_key)
    idx = {(r["matcher"], r["style"]): r for _, r in c.iterrows()}
    rows = []
    for m in sorted(set(c["matcher"])):
        cells = []
        for s in styles:
            r = idx.get((m, s))
            cells.append("—" if r is None else f"{r['change_pts']:+.1f} (−{r['lost']}/+{r['gained']})")
        rows.append([m] + cells)
    ref = c["reference"].iloc[0] if len(c) else "reference"
    return table(["matcher"] + [f"{s} vs {ref}" for s in styles], rows)


def robustness_figure(cells: pd.DataFrame, path: Path) -> Path | None:
    """A heat map of success (%): rows = matchers, columns = (log, style)."""
    if cells.empty:
        return None
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = sorted({(r.log, r.style) for r in cells.itertuples()}, key=lambda t: (t[0], style_key(t[1])))
    order = list(cells.groupby("matcher")["rate"].mean().sort_values(ascending=False).index)
    grid = np.full((len(order), len(cols)), np.nan)
    for r in cells.itertuples():
        grid[order.index(r.matcher), cols.index((r.log, r.style))] = r.rate
    fig, ax = plt.subplots(figsize=(1.0 + 0.55 * len(cols), 1.2 + 0.42 * len(order)))
    im = ax.imshow(grid, vmin=0, vmax=100, cmap="viridis", aspect="auto")
    for i in range(grid.shape[0]):
        for j in range(grid.shape[1]):
            if np.isfinite(grid[i, j]):
                ax.text(j, i, f"{grid[i, j]:.0f}", ha="center", va="center", fontsize=7,
                        color="white" if grid[i, j] < 60 else "black")
    ax.set_xticks(range(len(cols)), [f"{lg}\n{st}" for lg, st in cols], rotation=90, fontsize=7)
    ax.set_yticks(range(len(order)), order, fontsize=8)
    ax.set_title("success (%) by map style and changed world")
    fig.colorbar(im, ax=ax, fraction=0.03, pad=0.01)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def robustness_markdown(cells: pd.DataFrame, changes: pd.DataFrame, figure: str | None = None) -> str:
    """The whole section: the pooled table, one table per log, the paired changes, the figure."""
    if cells.empty:
        return "## Robustness\n\nNo dataset of this run has an `axis` (map style or changed world).\n"
    parts = ["## Robustness", "",
             "Success (≤ the run's thresholds) with Wilson 95 % intervals, per map style (the real logs' "
             "corrected scans drawn as other mapping tools draw them) and per changed world (simulated "
             "office: unmapped people and boxes occluding 0 / 10 / 25 % of the beams, or the furniture "
             "gone from the world but kept in the map). What each style is: docs/robustness.md.", "",
             "### All logs pooled, per style", "", robustness_table(cells), ""]
    for log in sorted(set(cells["log"])):
        parts += [f"### {log}", "", robustness_table(cells, log), "",
                  "Paired change against the reference style, points (scans lost / gained):", "",
                  changes_table(changes, log), ""]
    if figure:
        parts += [f"![success by style]({figure})", ""]
    return "\n".join(parts) + "\n"
