"""Why the paper's method fails, measured: ``tf``'s objective around the true pose of a few scans.

For a few scans of a run that has ``tf`` (the first scan of the office pool's cells ``d1-a1``,
``d2-a2`` and ``d3-a3``, else the first three scans with truth), ``tf``'s Err (Eq. 13 under the
literal reading, :func:`tfloc.paper.landscape.err_landscape`) is computed on a ±3 m grid at 5 cm
around the true position, at the true heading; per scan: whether the grid's global minimum lies
within 10 cm of the truth (the objective is well posed), how many local minima the grid has
(basins a local search can end in), and the rank correlation of Err with the distance to the
truth beyond 1 m (whether Err still points to the truth from afar). The report draws them
(:mod:`tfloc.report.landscape`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import spearmanr

from tfloc.core.pose import Pose
from tfloc.errors import TflocError
from tfloc.io.scenario import load_dataset
from tfloc.paper.landscape import (
    GRID,
    HALF_WIDTH_M,
    LandscapePanel,
    LandscapeStats,
    err_landscape,
    local_minima,
)

from .workspace import problem_of

CELLS = ("d1-a1", "d2-a2", "d3-a3")
MATCHER = "tf"


def _pick(p: pd.DataFrame, binned: list[str]) -> pd.DataFrame:
    """One ``tf`` scan of each cell of :data:`CELLS` from the datasets the paper's Scenarios II
    and III bin (``binned``), else the first three ``tf`` scans with truth."""
    rows = p[(p["matcher"] == MATCHER) & p["truth"]]
    pool = rows[rows["dataset"].isin(binned) & rows["group"].isin(CELLS)]
    chosen = pool.groupby("group", sort=True).head(1) if len(pool) else rows.head(3)
    return chosen.head(3)


def landscapes(p: pd.DataFrame, datasets: dict[str, Path], binned: list[str] = ()) -> list[LandscapePanel]:
    """The landscapes of :func:`_pick`'s scans of prepared rows ``p``; ``datasets`` maps dataset
    names to directories (``run.json``), ``binned`` names the datasets of Scenarios II/III."""
    panels = []
    for _, r in _pick(p, list(binned)).iterrows():
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
        stats = LandscapeStats(r["dataset"], r["scan_id"], scan.initial.distance_to(scan.true),
                               answer.distance_to(scan.true), float(d.ravel()[k]),
                               int(local_minima(land.err).sum()), float(rho))
        panels.append(LandscapePanel(land, scan.true, scan.initial, answer, stats))
    return panels
