"""How a matcher's cost grows: medians per level and log–log slopes (the scaling study).

The study (``tfloc scaling``) times every matcher per scan while one thing grows: the map's
area, the scanner's beam count or the initial offset. Per (matcher, axis, map kind, level) the
median CPU ms is taken; the slope of log(median CPU) against log(level) (least squares over the
levels, each level one point) says how the cost grows: 0 = flat, 1 = linear. A matcher *grows*
with an axis when the slope exceeds :data:`GROWS_SLOPE` (0.2: ×16 the area costs ×1.74 or more).
The same fit is applied to preparation CPU time and memory against map area. A matcher over
the study's budgets at a level (:func:`over_budget`) is not run at the larger levels of that axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
import pandas as pd

from tfloc.core.rows.timing import PrepRow, ScanRow, SkipRow

#: A slope of log cost against log size above this counts as "grows".
GROWS_SLOPE = 0.2

#: Columns of the study's tables: the fields of its typed rows (``scaling.csv``, ``prep.csv``
#: with matcher ``(map)`` for the map itself, ``skips.csv``), whose tables
#: (:func:`tfloc.io.table.frame_of`) the functions below read.
SCAN_COLUMNS = [f.name for f in fields(ScanRow)]
PREP_COLUMNS = [f.name for f in fields(PrepRow)]
SKIP_COLUMNS = [f.name for f in fields(SkipRow)]


@dataclass(frozen=True)
class Slope:
    """A least-squares line ``log y = intercept + slope · log x`` over ``n`` points."""

    slope: float
    intercept: float
    n: int

    @property
    def grows(self) -> bool:
        """Whether the cost grows with x (slope > :data:`GROWS_SLOPE`)."""
        return bool(self.slope > GROWS_SLOPE)


def fit_loglog(x: np.ndarray, y: np.ndarray) -> Slope:
    """The least-squares slope of log(y) on log(x) over the points with finite, positive x and
    y; NaN slope with fewer than two distinct x."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    lx, ly = np.log(x[ok]), np.log(y[ok])
    if np.unique(lx).size < 2:
        return Slope(math.nan, math.nan, int(ok.sum()))
    slope, intercept = np.polyfit(lx, ly, 1)
    return Slope(float(slope), float(intercept), int(ok.sum()))


def fit_linear(x: np.ndarray, y: np.ndarray) -> float:
    """The least-squares slope of y on x (y's unit per x's unit): an additive cost that a log–log
    slope hides while it is small next to the rest (e.g. ms per m² of map); NaN with fewer than
    two distinct finite x."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    if np.unique(x[ok]).size < 2:
        return math.nan
    return float(np.polyfit(x[ok], y[ok], 1)[0])


def level_table(rows: pd.DataFrame) -> pd.DataFrame:
    """Per (axis, kind, matcher, level): scans ``n``, ``size`` (the level's x: m², beams or
    metres), median and p90 CPU ms, median wall ms, the success rate and (when the rows have
    ``sys_ms``) the share of system time in the level's CPU time."""
    keys = ["axis", "kind", "matcher", "level"]
    g = rows.groupby(keys, sort=False)
    out = g.agg(size=("size", "first"), n=("cpu_ms", "size"), cpu_ms_median=("cpu_ms", "median"),
                cpu_ms_p90=("cpu_ms", lambda s: float(np.percentile(s, 90))),
                wall_ms_median=("wall_ms", "median"), success=("success", "mean"),
                **({"sys_share": ("sys_ms", "sum")} if "sys_ms" in rows else {}))
    out = out.reset_index()
    if "sys_share" in out:  # system CPU over all CPU of the level's calls
        out["sys_share"] /= g["cpu_ms"].sum().to_numpy()
    return out


def slope_table(levels: pd.DataFrame) -> pd.DataFrame:
    """Per (axis, kind, matcher): the log–log slope of median CPU against the level's size, the
    linear slope (ms per unit of size), the number of levels it spans, the cost at the first and
    last level and whether it grows."""
    out = []
    for (axis, kind, matcher), g in levels.groupby(["axis", "kind", "matcher"], sort=False):
        g = g.sort_values("size")
        s = fit_loglog(g["size"].to_numpy(), g["cpu_ms_median"].to_numpy())
        out.append({"axis": axis, "kind": kind, "matcher": matcher, "slope": s.slope, "levels": s.n,
                    "ms_per_unit": fit_linear(g["size"].to_numpy(), g["cpu_ms_median"].to_numpy()),
                    "first_ms": float(g["cpu_ms_median"].iloc[0]), "last_ms": float(g["cpu_ms_median"].iloc[-1]),
                    "first_size": float(g["size"].iloc[0]), "last_size": float(g["size"].iloc[-1]),
                    "grows": s.grows if math.isfinite(s.slope) else None})
    return pd.DataFrame(out)


def prep_slope_table(prep: pd.DataFrame) -> pd.DataFrame:
    """Per (kind, matcher): log–log slopes of preparation CPU seconds and retained memory (MB)
    against map area, over the maps whose preparation finished."""
    out = []
    done = prep[prep["status"] == "ok"]
    for (kind, matcher), g in done.groupby(["kind", "matcher"], sort=False):
        t = fit_loglog(g["size"].to_numpy(), g["prep_cpu_s"].to_numpy())
        m = fit_loglog(g["size"].to_numpy(), g["rss_delta_mb"].to_numpy())
        out.append({"kind": kind, "matcher": matcher, "time_slope": t.slope, "memory_slope": m.slope,
                    "maps": t.n})
    return pd.DataFrame(out)


def over_budget(rows: pd.DataFrame, prep: pd.DataFrame, level: str, budget_ms: float,
                prep_budget_s: float | None = None) -> dict[str, str]:
    """The matchers of one level's rows (``SCAN_COLUMNS``) over a budget, each with why: median
    CPU per scan above ``budget_ms`` (ms), or preparation CPU (``prep``'s ``prep_cpu_s``) above
    ``prep_budget_s`` (s; ``None``: not checked). A matcher without a finite median is not."""
    med = rows.groupby("matcher", sort=False)["cpu_ms"].median()
    prep_s = dict(zip(prep["matcher"], prep["prep_cpu_s"], strict=True)) if len(prep) else {}
    out = {}
    for m, ms in med.items():
        if ms > budget_ms:
            out[m] = f"median {ms:.0f} ms > {budget_ms:g} ms at {level}"
        elif prep_budget_s is not None and prep_s.get(m, 0.0) > prep_budget_s:
            out[m] = f"prepare {prep_s[m]:.0f} s > {prep_budget_s:g} s at {level}"
    return out
