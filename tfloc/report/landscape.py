"""Why the paper's method fails, from measurements: its objective around the true pose.

For a few scans of a run that has ``tf`` (the first scan of the office pool's cells ``d1-a1``,
``d2-a2`` and ``d3-a3``, else the first three scans with truth), ``tf``'s Err (Eq. 13 under the
literal reading, :func:`tfloc.paper.landscape.err_landscape`) is computed on a ±3 m grid at 5 cm
around the true position, at the true heading, and drawn as a map with the truth, the initial
guess, ``tf``'s answer and the grid's local minima. Beside it, per scan: whether the grid's global
minimum lies within 10 cm of the truth (the objective is well posed), how many local minima the
grid has (basins a local search can end in), and the rank correlation of Err with the distance to
the truth beyond 1 m (whether Err still points to the truth from afar).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from scipy.stats import spearmanr

from tfloc.core.pose import Pose
from tfloc.errors import TflocError
from tfloc.harness.workspace import load_dataset, problem_of
from tfloc.paper.landscape import err_landscape, local_minima

HALF_WIDTH_M = 3.0
GRID = 121                      # 5 cm cells over ±3 m
CELLS = ("d1-a1", "d2-a2", "d3-a3")
MATCHER = "tf"


@dataclass(frozen=True)
class LandscapeStats:
    """What one scan's landscape shows (distances in metres)."""

    dataset: str
    scan_id: str
    init_dist_m: float
    answer_dist_m: float
    global_min_dist_m: float
    minima: int
    far_rank_correlation: float


def _pick(p: pd.DataFrame, binned: list[str]) -> pd.DataFrame:
    """One ``tf`` scan of each cell of :data:`CELLS` from the datasets the paper's Scenarios II
    and III bin (``binned``), else the first three ``tf`` scans with truth."""
    rows = p[(p["matcher"] == MATCHER) & p["truth"]]
    pool = rows[rows["dataset"].isin(binned) & rows["group"].isin(CELLS)]
    chosen = pool.groupby("group", sort=True).head(1) if len(pool) else rows.head(3)
    return chosen.head(3)


def draw_landscapes(run_dir: Path, p: pd.DataFrame, datasets: dict[str, Path],
                    binned: list[str] = ()) -> tuple[Path | None, list[LandscapeStats]]:
    """Compute and draw the landscapes of :func:`_pick`'s scans; ``datasets`` maps dataset names to
    directories (``run.json``), ``binned`` names the datasets of Scenarios II/III. Returns the
    figure (relative to ``run_dir``) and the statistics."""
    chosen = _pick(p, list(binned))
    if chosen.empty:
        return None, []
    panels, stats = [], []
    for _, r in chosen.iterrows():
        try:
            sc, scans = load_dataset(str(datasets[r["dataset"]]))
            scan = scans[r["scan_id"]]
            problem = problem_of(sc, scan)
        except (KeyError, OSError, TflocError):
            continue
        try:
            land = err_landscape(problem, scan.true, HALF_WIDTH_M, GRID)
        except ValueError:
            continue
        d = land.distance_to(scan.true.x, scan.true.y)
        finite = np.isfinite(land.err)
        k = np.nanargmin(land.err)
        far = finite & (d > 1.0)
        rho = spearmanr(land.err[far], d[far]).statistic if far.sum() > 2 else np.nan
        answer = Pose(float(r["est_x"]), float(r["est_y"]), float(r["est_theta"]))
        stats.append(LandscapeStats(r["dataset"], r["scan_id"], scan.initial.distance_to(scan.true),
                                    answer.distance_to(scan.true), float(d.ravel()[k]),
                                    int(local_minima(land.err).sum()), float(rho)))
        panels.append((land, scan, answer, stats[-1]))
    if not panels:
        return None, []
    fig = Figure(figsize=(5.0 * len(panels), 5.0), layout="constrained")
    for i, (land, scan, answer, st) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), i + 1)
        im = ax.pcolormesh(land.xs, land.ys, land.err, shading="nearest", cmap="viridis")
        my, mx = np.nonzero(local_minima(land.err))
        ax.plot(land.xs[mx], land.ys[my], ".", color="white", ms=1.5, label="local minima")
        for pose, style, label in ((scan.true, "*", "truth"), (scan.initial, "o", "initial guess"),
                                   (answer, "X", "tf's answer")):
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
    return rel, stats


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
