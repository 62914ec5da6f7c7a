"""Why the paper's method fails, drawn: ``tf``'s objective around the true pose of a few scans
(computed by :mod:`tfloc.harness.landscape`), as a map with the truth, the initial guess, ``tf``'s
answer and the grid's local minima, and a table of what each shows."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from tfloc.paper.landscape import GRID, HALF_WIDTH_M, LandscapePanel, LandscapeStats, local_minima


def draw_landscapes(run_dir: Path, panels: list[LandscapePanel]) -> tuple[Path | None, list[LandscapeStats]]:
    """Draw the landscapes ``panels`` into ``run_dir/figures/err_landscape.png``; returns the
    figure (relative to ``run_dir``) and the statistics."""
    if not panels:
        return None, []
    fig = Figure(figsize=(5.0 * len(panels), 5.0), layout="constrained")
    for i, panel in enumerate(panels):
        land, st = panel.land, panel.stats
        ax = fig.add_subplot(1, len(panels), i + 1)
        im = ax.pcolormesh(land.xs, land.ys, land.err, shading="nearest", cmap="viridis")
        my, mx = np.nonzero(local_minima(land.err))
        ax.plot(land.xs[mx], land.ys[my], ".", color="white", ms=1.5, label="local minima")
        for pose, style, label in ((panel.truth, "*", "truth"), (panel.initial, "o", "initial guess"),
                                   (panel.answer, "X", "tf's answer")):
            ax.plot(pose.x, pose.y, style, color="red" if label == "tf's answer" else "black",
                    ms=11, mec="white", label=label)
        ax.set_xlim(land.xs[0], land.xs[-1])
        ax.set_ylim(land.ys[0], land.ys[-1])
        ax.set_aspect("equal")
        ax.set_title(f"{st.dataset}/{st.scan_id}: {st.minima} local minima", fontsize=9)
        ax.set_xlabel("x (m)")
        fig.colorbar(im, ax=ax, shrink=0.8, label="Err (rad)")
    fig.axes[0].set_ylabel("y (m)")
    fig.axes[0].legend(loc="upper left", fontsize=7, framealpha=0.8)
    rel = Path("figures") / "err_landscape.png"
    (run_dir / rel).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(run_dir / rel, dpi=100)
    return rel, [p.stats for p in panels]


def landscape_section(figure: Path | None, stats: list[LandscapeStats]) -> str:
    """The report's section on ``tf``'s objective around the truth."""
    if figure is None:
        return ""
    rows = "\n".join(
        f"| {s.dataset}/{s.scan_id} | {100 * s.init_dist_m:.0f} | {100 * s.answer_dist_m:.0f} | "
        f"{100 * s.global_min_dist_m:.0f} | {s.minima} | {s.far_rank_correlation:.2f} |" for s in stats)
    return (
        "## Why `tf` fails: its objective around the truth\n\n"
        f"`tf`'s Err (Eq. 13, literal reading) on a ±{HALF_WIDTH_M:g} m grid at "
        f"{200 * HALF_WIDTH_M / (GRID - 1):.0f} cm around the true position, at the true heading. "
        "Err is well posed when its global minimum lies at the truth; a local search can stop in "
        "any local minimum; the rank correlation says whether Err still falls towards the truth "
        "from more than 1 m away (1: perfectly, 0: not at all).\n\n"
        "| scan | initial offset (cm) | tf's answer from the truth (cm) | grid's global minimum from the "
        "truth (cm) | local minima | rank correlation of Err with distance beyond 1 m |\n"
        "|---|---|---|---|---|---|\n" + rows + "\n\n"
        f"![Err around the truth]({figure.as_posix()})\n")
