"""A tracking report's figures: each sequence's trajectories on the map per matcher, zoomed to the
path with axes in metres, and the distance error over the distance travelled."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from tfloc.core.tracker import DeadReckoning
from tfloc.evaluation.sequences import poses as pose_columns
from tfloc.evaluation.trajectory import LOST_DIST_M, errors, path_length
from tfloc.io.scenario import Scenario

from .figures import MAP_SPACING_M, colours

DEAD_RECKONING = DeadReckoning.name  # the floor, shown last


def order(matchers) -> list[str]:
    """Matchers by name, dead reckoning last."""
    ms = sorted(set(matchers) - {DEAD_RECKONING})
    return ms + ([DEAD_RECKONING] if DEAD_RECKONING in set(matchers) else [])


def path_box(true: np.ndarray, est: np.ndarray, margin_m: float = 2.0,
             reach_m: float = 10.0) -> tuple[tuple[float, float], tuple[float, float]]:
    """The x and y limits (metres) of a trajectory panel: the true path and the estimates within
    ``reach_m`` of its box, with ``margin_m`` around (the panel zooms to the path, not the map;
    an estimate lost far away shows as a point at the edge of its direction)."""
    t = true[np.isfinite(true[:, :2]).all(axis=1), :2]
    if not len(t):
        t = est[np.isfinite(est[:, :2]).all(axis=1), :2]
    if not len(t):
        return (0.0, 1.0), (0.0, 1.0)
    lo, hi = t.min(axis=0), t.max(axis=0)
    e = est[np.isfinite(est[:, :2]).all(axis=1), :2]
    near = e[((e >= lo - reach_m) & (e <= hi + reach_m)).all(axis=1)]
    if len(near):
        lo, hi = np.minimum(lo, near.min(axis=0)), np.maximum(hi, near.max(axis=0))
    return (float(lo[0] - margin_m), float(hi[0] + margin_m)), (float(lo[1] - margin_m), float(hi[1] + margin_m))


def fig_trajectories(scenario: Scenario, the_map, rows: pd.DataFrame, path: Path) -> Path:
    """One panel per matcher: the map, the true trajectory and the matcher's estimates (scans
    lost, > 0.5 m off, in red); zoomed to the path (:func:`path_box`), axes in metres."""
    ms = order(rows["matcher"].unique())
    mp, _ = the_map.sample_points(MAP_SPACING_M)
    ncol = min(3, len(ms))
    nrow = math.ceil(len(ms) / ncol)
    fig = Figure(figsize=(5.2 * ncol, 4.2 * nrow), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrow, ncol)).ravel()
    box = path_box(pose_columns(rows, "true"), pose_columns(rows, "est"))
    for ax, m in zip(axes, ms, strict=False):
        g = rows[rows["matcher"] == m]
        t, e = pose_columns(g, "true"), pose_columns(g, "est")
        ax.scatter(mp[:, 0], mp[:, 1], s=0.2, c="black", rasterized=True)
        ax.plot(t[:, 0], t[:, 1], "-", color="#2ca02c", lw=1.2, label="truth")
        ax.plot(e[:, 0], e[:, 1], "-", color="#1f77b4", lw=0.8, label="estimate")
        ok = np.isfinite(t).all(axis=1)
        d = np.full(len(t), np.nan)
        d[ok] = errors(e[ok], t[ok])[0]
        lost = d > LOST_DIST_M
        ax.plot(e[lost, 0], e[lost, 1], ".", color="#d62728", ms=2, label="lost (> 0.5 m)")
        ax.set_title(m, fontsize=10)
        ax.set_aspect("equal")
        ax.set_xlim(*box[0])
        ax.set_ylim(*box[1])
        ax.set_xlabel("x (m)", fontsize=8)
        ax.set_ylabel("y (m)", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes[len(ms):]:
        ax.set_visible(False)
    axes[0].legend(fontsize=7, loc="best")
    fig.suptitle(f"{scenario.name}: trajectories on the map", fontsize=11)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    return path


def fig_error_distance(scenario: Scenario, rows: pd.DataFrame, path: Path) -> Path:
    """Distance error (log scale) over the true distance travelled, one line per matcher."""
    ms = order(rows["matcher"].unique())
    col = colours(ms)
    fig = Figure(figsize=(8, 3.6), layout="constrained")
    ax = fig.subplots()
    for m in ms:
        g = rows[rows["matcher"] == m]
        t, e = pose_columns(g, "true"), pose_columns(g, "est")
        ok = np.isfinite(t).all(axis=1)
        if ok.sum() < 2:
            continue
        ax.plot(path_length(t[ok]), np.maximum(errors(e[ok], t[ok])[0], 1e-3), lw=0.8,
                color=col[m], label=m)
    ax.axhline(LOST_DIST_M, color="grey", ls="--", lw=0.8)
    ax.set_yscale("log")
    ax.set_xlabel("distance travelled (m)")
    ax.set_ylabel("distance error (m)")
    ax.set_title(f"{scenario.name}: error over distance travelled (dashed: lost)", fontsize=10)
    ax.legend(fontsize=7, ncol=3)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    return path
