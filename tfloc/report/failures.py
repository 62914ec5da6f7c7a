"""Failure pictures: what a failed scan of each matcher looks like.

For each matcher and each failure outcome (``local-optimum``, ``ambiguous``, ``no-answer``) a
few representative failed scans are chosen deterministically: ordered by distance error (a
no-answer without a pose by initial offset, then scan id), the one at the median and the worst.
Each becomes ``figures/failures/<matcher>/<dataset>-<scan>.png``: the map around the scan, and
the scan's points drawn at the true pose (green), at the initial pose (grey) and at the estimate
(red), each pose as a dot with an arrow along its heading. The scans and maps are read from the datasets the run
recorded in ``run.json`` (:mod:`tfloc.io.scenario`); a dataset that is no longer there is skipped.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from tfloc.core.pose import Pose
from tfloc.errors import TflocError
from tfloc.evaluation.outcome import OUTCOMES
from tfloc.io.scenario import Scan, Scenario, load_dataset, map_for

FAILURES = tuple(OUTCOMES[1:])  # local-optimum, ambiguous, no-answer
WINDOW_MARGIN_M = 1.0
MAX_WINDOW_M = 30.0
MAP_SPACING_M = 0.03


@dataclass(frozen=True)
class FailurePicture:
    """One drawn failure: where its PNG is (relative to the run directory) and what it shows."""

    matcher: str
    outcome: str
    dataset: str
    scan_id: str
    dist_err_cm: float
    path: Path


def representatives(g: pd.DataFrame) -> pd.DataFrame:
    """The median-error and the worst row of one matcher's failures of one outcome (deterministic)."""
    key = g["dist_err_cm"].fillna(np.inf)
    order = g.assign(_k=key, _i=pd.to_numeric(g["init_dist_err_m"], errors="coerce"))
    order = order.sort_values(["_k", "_i", "dataset", "scan_id"], kind="stable")
    picks = sorted({(len(order) - 1) // 2, len(order) - 1})
    return order.iloc[picks]


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_") or "matcher"


def _pose(r: pd.Series, prefix: str) -> Pose | None:
    v = [pd.to_numeric(r.get(f"{prefix}_{k}"), errors="coerce") for k in ("x", "y", "theta")]
    return Pose(*map(float, v)) if all(np.isfinite(v)) else None


def _draw(path: Path, scenario: Scenario, scan: Scan, r: pd.Series, cache: dict) -> Path:
    """One failure picture (see the module docstring)."""
    local = scenario.laser.to_points(scan.ranges)
    poses = {"truth": (_pose(r, "true"), "#2ca02c"), "initial": (_pose(r, "init"), "#7f7f7f"),
             "estimate": (_pose(r, "est"), "#d62728")}
    drawn = {k: (p, c, p.transform(local)) for k, (p, c) in poses.items() if p is not None}
    allxy = np.vstack([xy for _, _, xy in drawn.values()] + [np.array([[p.x, p.y]]) for p, _, _ in drawn.values()])
    lo, hi = allxy.min(axis=0) - WINDOW_MARGIN_M, allxy.max(axis=0) + WINDOW_MARGIN_M
    centre = drawn["truth"][0].xy if "truth" in drawn else 0.5 * (lo + hi)
    lo, hi = np.maximum(lo, centre - MAX_WINDOW_M / 2), np.minimum(hi, centre + MAX_WINDOW_M / 2)
    mp, _ = map_for(scenario, scan, cache).sample_points(MAP_SPACING_M)
    mp = mp[np.all((mp >= lo) & (mp <= hi), axis=1)]
    fig = Figure(figsize=(6.4, 6.4), layout="constrained")
    ax = fig.subplots()
    ax.scatter(mp[:, 0], mp[:, 1], s=0.6, c="black", label="map", rasterized=True)
    for name, (p, colour, xy) in drawn.items():
        ax.scatter(xy[:, 0], xy[:, 1], s=3, c=colour, label=f"scan at {name}")
        ax.plot([p.x], [p.y], "o", color=colour, ms=6, mec="black", mew=0.6)
        ax.annotate("", xy=(p.x + 0.7 * np.cos(p.theta), p.y + 0.7 * np.sin(p.theta)), xytext=(p.x, p.y),
                    arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 1.8, "mutation_scale": 14})
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(loc="upper right", fontsize=8, markerscale=3)
    err = r.get("dist_err_cm")
    err_txt = (f"error {err:.1f} cm / {r.get('orient_err_deg'):.2f}°" if pd.notna(err)
               else f"status {r.get('status')}")
    ax.set_title(f"{r['matcher']}: {r['outcome_eval']} on {r['dataset']}/{r['scan_id']}\n"
                 f"initial offset {100 * float(r['init_dist_err_m']):.0f} cm, {err_txt}", fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def draw_failures(run_dir: Path, p: pd.DataFrame, datasets: dict[str, Path]) -> list[FailurePicture]:
    """Draw the representative failures of every matcher of prepared rows ``p``; ``datasets``
    maps dataset names to their directories (``run.json``). Returns what was drawn."""
    fails = p[p["truth"] & p["outcome_eval"].isin(FAILURES)]
    out: list[FailurePicture] = []
    loaded: dict[str, tuple[Scenario, dict[str, Scan]] | None] = {}
    cache: dict = {}
    for (matcher, outcome), g in fails.groupby(["matcher", "outcome_eval"], sort=True):
        for _, r in representatives(g).iterrows():
            name = r["dataset"]
            if name not in loaded:
                try:
                    loaded[name] = load_dataset(str(datasets[name]))
                except (KeyError, OSError, TflocError):
                    loaded[name] = None
            if loaded[name] is None or r["scan_id"] not in loaded[name][1]:
                continue
            scenario, scans = loaded[name]
            rel = Path("figures") / "failures" / _safe(matcher) / f"{_safe(name)}-{_safe(r['scan_id'])}.png"
            _draw(run_dir / rel, scenario, scans[r["scan_id"]], r, cache)
            out.append(FailurePicture(matcher, outcome, name, r["scan_id"], float(r["dist_err_cm"]), rel))
    return out


def failures_section(pictures: list[FailurePicture]) -> str:
    """The report's list of failure pictures, per matcher and outcome."""
    if not pictures:
        return "_No failures to draw (or the run's datasets are not available)._\n"
    lines = ["For each matcher and failure outcome, the failed scan at the median distance error and "
             "the worst (no-answers without a pose: by initial offset). Green: the scan at the true "
             "pose; grey: at the initial pose; red: at the estimate.\n"]
    for matcher in dict.fromkeys(f.matcher for f in pictures):
        cells = []
        for outcome in FAILURES:
            links = [f"[{f.dataset}/{f.scan_id}]({f.path.as_posix()})"
                     + ("" if np.isnan(f.dist_err_cm) else f" ({f.dist_err_cm:.0f} cm)")
                     for f in pictures if f.matcher == matcher and f.outcome == outcome]
            if links:
                cells.append(f"{outcome}: " + ", ".join(links))
        lines.append(f"- `{matcher}`: " + "; ".join(cells))
    return "\n".join(lines) + "\n"
