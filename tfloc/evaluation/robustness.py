"""Robustness: success per matcher on every map style and every changed world (pure).

A dataset's place on the axes comes from its ``scenario.json`` (``"axis": {"log", "style"}``,
written by ``tfloc real-data`` and ``tfloc generate``), never from its name. Success rates carry
Wilson 95 % intervals (:func:`tfloc.evaluation.stats.wilson`); the change of each style against
the log's reference style (``as-built`` for a real log, ``clutter-0`` in simulation) is paired
over the same scans. The section is drawn by :mod:`tfloc.report.robustness`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from tfloc.core.rows.robustness import RobustnessRow

from .stats import wilson

#: Style order of the columns (others follow in name order); the first of each log that is
#: present is the reference the changes are measured from.
STYLE_ORDER = ("as-built", "hits-only", "thick-1", "thick-2", "cartographer", "gmapping", "incomplete",
               "clutter-0", "clutter-10", "clutter-25", "furniture-gone")
REFERENCE = ("as-built", "clutter-0")


@dataclass(frozen=True)
class Axis:
    """Where a dataset sits: the log (or simulated world) and the map style or world change."""

    log: str
    style: str


def axes_of(datasets: Iterable[tuple[str, dict]]) -> dict[str, Axis]:
    """``{dataset name: Axis}`` from ``(name, scenario extra fields)`` pairs; datasets without an
    ``axis`` field are left out."""
    out = {}
    for name, extra in datasets:
        ax = extra.get("axis")
        if isinstance(ax, dict) and isinstance(ax.get("log"), str) and isinstance(ax.get("style"), str):
            out[name] = Axis(ax["log"], ax["style"])
    return out


def style_key(style: str) -> tuple[int, str]:
    return (STYLE_ORDER.index(style) if style in STYLE_ORDER else len(STYLE_ORDER), style)


def robustness_cells(prepared: pd.DataFrame, axes: dict[str, Axis]) -> list[RobustnessRow]:
    """One row per (matcher, log, style): ``n`` scans with truth, ``k`` successes, ``rate`` (%),
    ``lo``/``hi`` (Wilson 95 %, %), ``median_cm`` (median distance error over all its scans) and
    ``cpu_ms`` (median CPU ms per scan). ``prepared`` is
    :func:`tfloc.evaluation.metrics.prepare` of a run's estimates."""
    p = prepared[prepared["dataset"].isin(list(axes)) & prepared["truth"].astype(bool)].copy()
    p["log"] = p["dataset"].map(lambda d: axes[d].log)
    p["style"] = p["dataset"].map(lambda d: axes[d].style)
    rows = []
    for (matcher, log, style), g in p.groupby(["matcher", "log", "style"], sort=False):
        n, k = len(g), int((g["outcome_eval"] == "success").sum())
        lo, hi = wilson(k, n)
        rows.append(RobustnessRow(matcher, log, style, n, k, 100.0 * k / n if n else np.nan, 100.0 * lo,
                                  100.0 * hi, float(g["dist_err_cm"].median()), float(g["cpu_ms"].median())))
    return rows


def paired_changes(prepared: pd.DataFrame, axes: dict[str, Axis]) -> pd.DataFrame:
    """Per (matcher, log, style ≠ reference): the change of success in points against the log's
    reference style on the scans both have (matched by scan id), with ``n`` and the scans only
    the reference (``lost``) or only the style (``gained``) solved."""
    p = prepared[prepared["dataset"].isin(list(axes)) & prepared["truth"].astype(bool)].copy()
    p["log"] = p["dataset"].map(lambda d: axes[d].log)
    p["style"] = p["dataset"].map(lambda d: axes[d].style)
    p["ok"] = p["outcome_eval"] == "success"
    rows = []
    for (matcher, log), g in p.groupby(["matcher", "log"], sort=False):
        styles = sorted(set(g["style"]), key=style_key)
        ref = next((s for s in styles if s in REFERENCE), None)
        if ref is None:
            continue
        base = g[g["style"] == ref].set_index("scan_id")["ok"]
        for style in styles:
            if style == ref:
                continue
            other = g[g["style"] == style].set_index("scan_id")["ok"]
            both = base.index.intersection(other.index)
            a, b = base.loc[both], other.loc[both]
            n = len(both)
            rows.append({"matcher": matcher, "log": log, "style": style, "reference": ref, "n": n,
                         "change_pts": 100.0 * (b.mean() - a.mean()) if n else np.nan,
                         "lost": int((a & ~b).sum()), "gained": int((~a & b).sum())})
    return pd.DataFrame(rows, columns=["matcher", "log", "style", "reference", "n", "change_pts", "lost", "gained"])
