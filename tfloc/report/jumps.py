"""Pictures of a tracker's first jumps: where an estimate left its prediction by more than 1 m.

A tracker that leaves a correct track for a look-alike place shows it as a jump
(:data:`tfloc.evaluation.trajectory.JUMP_M`; the prediction is the row's ``init_*``, the last
estimate composed with the odometry). One panel per jump, the first :data:`PER_MATCHER` of each
matcher of one sequence: the map within :data:`HALF_M` (or more, to hold both ends) of the jump, the corrected poses nearby
(truth, where the row has it), the matcher's estimates :data:`CONTEXT` scans before and after,
the prediction and the estimate it jumped to. Dead reckoning (``odometry``) has no jumps.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from tfloc.evaluation.sequences import poses as pose_columns
from tfloc.evaluation.trajectory import JUMP_M

from .figures import MAP_SPACING_M

PER_MATCHER = 3  #: jumps drawn per matcher
CONTEXT = 30  #: scans drawn before and after a jump
HALF_M = 4.0  #: half the side of a panel (metres)
EVENT_GAP = 10  #: a jump within this many scans of a drawn one is the same event, not drawn


def _xy(g: pd.DataFrame, prefix: str) -> np.ndarray:
    return pose_columns(g, prefix)[:, :2]


def first_jumps(rows: pd.DataFrame, per_matcher: int = PER_MATCHER) -> list[tuple[str, int]]:
    """``(matcher, position in its rows)`` of the first ``per_matcher`` jump events of each
    matcher of one sequence's rows (each matcher's rows in scan order; a jump within
    :data:`EVENT_GAP` scans of the last one kept is the same event), matchers in first-seen order."""
    out = []
    for m, g in rows.groupby("matcher", sort=False):
        d = np.hypot(*(_xy(g, "est") - _xy(g, "init")).T)
        kept: list[int] = []
        for i in np.flatnonzero(d > JUMP_M):
            if len(kept) == per_matcher:
                break
            if not kept or i - kept[-1] >= EVENT_GAP:
                kept.append(int(i))
        out += [(m, i) for i in kept]
    return out


def fig_jumps(name: str, the_map, rows: pd.DataFrame, path: Path) -> Path | None:
    """The first jumps of every matcher of one sequence (module notes), or ``None`` if none."""
    jumps = first_jumps(rows)
    if not jumps:
        return None
    mp, _ = the_map.sample_points(MAP_SPACING_M)
    ncol = min(PER_MATCHER, len(jumps))
    nrow = math.ceil(len(jumps) / ncol)
    fig = Figure(figsize=(3.6 * ncol, 3.6 * nrow), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrow, ncol)).ravel()
    for ax, (m, i) in zip(axes, jumps, strict=False):
        g = rows[rows["matcher"] == m]
        est, pred, true = _xy(g, "est"), _xy(g, "init"), _xy(g, "true")
        c = (est[i] + pred[i]) / 2.0
        half = max(HALF_M, float(np.hypot(*(est[i] - pred[i]))) / 2.0 + 1.0)
        lo, hi = max(0, i - CONTEXT), min(len(g), i + CONTEXT + 1)
        near = (np.abs(mp - c) <= half).all(axis=1)
        ax.scatter(mp[near, 0], mp[near, 1], s=0.3, c="black", rasterized=True)
        ax.plot(true[lo:hi, 0], true[lo:hi, 1], "o", color="#2ca02c", ms=2.5, label="truth")
        ax.plot(est[lo:i, 0], est[lo:i, 1], "-", color="#1f77b4", lw=0.9, label="estimates before")
        ax.plot(est[i:hi, 0], est[i:hi, 1], "-", color="#ff7f0e", lw=0.9, label="after")
        ax.annotate("", xy=est[i], xytext=pred[i],
                    arrowprops={"arrowstyle": "->", "color": "#d62728", "lw": 1.2})
        ax.plot(*pred[i], "o", mfc="none", color="#d62728", ms=6, label="prediction")
        ax.plot(*est[i], "x", color="#d62728", ms=7, label="jumped to")
        ax.set_xlim(c[0] - half, c[0] + half)
        ax.set_ylim(c[1] - half, c[1] + half)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=6)
        jump = float(np.hypot(*(est[i] - pred[i])))
        ax.set_title(f"{m}: scan {g['scan_id'].iloc[i]}, {jump:.1f} m", fontsize=8)
    for ax in axes[len(jumps):]:
        ax.set_visible(False)
    axes[0].legend(fontsize=6, loc="best")
    fig.suptitle(f"{name}: the first jumps (> {JUMP_M:g} m from the prediction) of each tracker",
                 fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    return path


__all__ = ["CONTEXT", "EVENT_GAP", "HALF_M", "PER_MATCHER", "fig_jumps", "first_jumps"]
