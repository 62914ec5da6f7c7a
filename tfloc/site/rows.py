"""A run directory's headline rows, as the site reads them: ``headline.csv`` (written by
``tfloc report``) where the run has one; otherwise, until the run is reported again, rows
derived from the tables the run already has, marked *provisional*: ``tracking.csv`` (tracked
share with Wilson's interval per sequence, pooled over sequences by the same bootstrap as the
headline), ``relocalization.csv`` (top-1) or ``summary.csv`` (success per dataset, pooled by
Wilson over scans). A provisional row has no paired test (verdict empty, never marked best),
and a pooled one no error or CPU figure (medians do not pool). Each dataset's kind (real or
simulated) comes with the rows, read from its ``scenario.json`` (:mod:`tfloc.site.runs`).
Percentages in %, errors in cm, CPU in ms."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from tfloc.core.modes import GLOBAL, SEQUENCE, mode_of
from tfloc.core.run import Run
from tfloc.evaluation.headline import POOLED, HeadlineRow, read_headline
from tfloc.evaluation.stats import wilson
from tfloc.evaluation.trajectory import pooled_share

from .runs import dataset_kinds, run_info

#: where a run's rows came from, best first
SOURCES = ("headline.csv", "tracking.csv", "relocalization.csv", "summary.csv")


@dataclass(frozen=True)
class RunRows:
    """The headline rows of one run directory (``source``: the file they came from, "" where
    the run has none; ``exists``: the directory is there; ``kinds``: dataset → ``real`` or
    ``simulated``, for the datasets whose ``scenario.json`` could be read)."""

    name: str
    path: Path
    exists: bool
    source: str = ""
    rows: list[HeadlineRow] = field(default_factory=list)
    kinds: dict[str, str] = field(default_factory=dict)

    @property
    def provisional(self) -> bool:
        """Rows not from ``headline.csv``: no paired test yet."""
        return bool(self.source) and self.source != SOURCES[0]


def _row(mode: str, scope: str, matcher: str, value: float, lo: float, hi: float, n: int,
         error_cm: float, cpu_ms: float) -> HeadlineRow:
    m = mode_of(mode)
    return HeadlineRow(mode, scope, 0, matcher, m.measure, value, lo, hi, n, error_cm, m.error, cpu_ms, "", "", math.nan)


def _ranked(rows: list[HeadlineRow]) -> list[HeadlineRow]:
    """Ranks within each (mode, scope), ordered as the headline orders them."""
    def nz(v: float, fill: float) -> float:
        return fill if math.isnan(v) else v

    out: list[HeadlineRow] = []
    for key in dict.fromkeys((r.mode, r.scope) for r in rows):
        mine = sorted((r for r in rows if (r.mode, r.scope) == key),
                      key=lambda r: (-nz(r.value_pct, -1.0), nz(r.error_cm, math.inf),
                                     nz(r.cpu_ms, math.inf), r.matcher))
        out += [HeadlineRow(**{**r.__dict__, "rank": i + 1}) for i, r in enumerate(mine)]
    return out


def _pool(per: dict[str, list[tuple[int, int]]], mode: str, bootstrap: bool) -> list[HeadlineRow]:
    """Pooled rows from (k, n) per dataset of each matcher."""
    out = []
    for m, kn in per.items():
        k, n = [a for a, _ in kn], [b for _, b in kn]
        if bootstrap:
            v, lo, hi = pooled_share(k, n)
        else:
            v = sum(k) / sum(n) if sum(n) else math.nan
            lo, hi = wilson(sum(k), sum(n))
        out.append(_row(mode, POOLED, m, 100 * v, 100 * lo, 100 * hi, sum(n), math.nan, math.nan))
    return out


def _from_tracking(df: pd.DataFrame) -> list[HeadlineRow]:
    rows, per = [], {}
    for r in df.to_dict("records"):
        k, n = int(r["n_tracked"]), int(r["n_truth"])
        lo, hi = wilson(k, n)
        rows.append(_row(SEQUENCE.key, str(r["dataset"]), str(r["matcher"]), 100 * k / n if n else math.nan,
                         100 * lo, 100 * hi, n, 100 * float(r["ape_rmse_m"]), float(r["cpu_ms_median"])))
        per.setdefault(str(r["matcher"]), []).append((k, n))
    pooled = _pool(per, SEQUENCE.key, bootstrap=True) if df["dataset"].nunique() > 1 else []
    return pooled + rows


def _from_relocalization(df: pd.DataFrame) -> list[HeadlineRow]:
    rows, per = [], {}
    for r in df.to_dict("records"):
        n = int(r["n"])
        k = round(float(r["top1"]) * n)
        rows.append(_row(GLOBAL.key, str(r["dataset"]), str(r["matcher"]), 100 * float(r["top1"]),
                         100 * float(r["top1_lo"]), 100 * float(r["top1_hi"]), n, math.nan,
                         float(r["cpu_ms_median"])))
        per.setdefault(str(r["matcher"]), []).append((k, n))
    pooled = _pool(per, GLOBAL.key, bootstrap=False) if df["dataset"].nunique() > 1 else []
    return pooled + rows


def _from_summary(df: pd.DataFrame, info: Run) -> list[HeadlineRow]:
    df = df[(df["grouping"] == "dataset") & (df["bin"] == "all")]
    rows, per = [], {}
    modes = {d: info.mode(d) for d in dict.fromkeys(str(d) for d in df["dataset"])}
    for r in df.to_dict("records"):
        d = str(r["dataset"])
        mode = modes[d]
        n, k = int(r["n_truth"]), int(r["n_success"])
        rows.append(_row(mode, d, str(r["matcher"]), float(r["success_rate_pct"]), float(r["success_lo_pct"]),
                         float(r["success_hi_pct"]), n, float(r["dist_median_cm"]), float(r["cpu_median_ms"])))
        per.setdefault(mode, {}).setdefault(str(r["matcher"]), []).append((k, n))
    pooled = []
    for mode, by in per.items():
        if len({r.scope for r in rows if r.mode == mode}) > 1:
            pooled += _pool(by, mode, bootstrap=False)
    return pooled + rows


def run_rows(root: Path, name: str) -> RunRows:
    """The headline rows of ``root/name``: from ``headline.csv``, else provisional ones from the
    first of the run's other tables (:data:`SOURCES`), else none."""
    path = Path(root) / name
    if not path.is_dir():
        return RunRows(name, path, False)
    info = run_info(path)

    def found(source: str, rows: list[HeadlineRow]) -> RunRows:
        return RunRows(name, path, True, source, rows,
                       dataset_kinds(info, [r.scope for r in rows if r.scope != POOLED], Path(root).resolve().parent))

    if (path / SOURCES[0]).is_file():
        return found(SOURCES[0], read_headline(path / SOURCES[0]))
    for source in SOURCES[1:]:
        f = path / source
        if not f.is_file():
            continue
        df = pd.read_csv(f, keep_default_na=False, na_values=[""])
        if df.empty:
            continue
        if source == "tracking.csv":
            rows = _from_tracking(df)
        elif source == "relocalization.csv":
            rows = _from_relocalization(df)
        else:
            rows = _from_summary(df, info)
        return found(source, _ranked(rows))
    return RunRows(name, path, True)
