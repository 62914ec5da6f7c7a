"""A run's poses as TUM trajectories, so that ``evo_ape``/``evo_rpe`` and other tools read them.

From ``RUN/estimates.csv`` (columns ``dataset, scan_id, matcher, true_*, init_*, est_*``), for
each dataset: ``reference.tum`` (true poses), ``initial.tum`` (initial guesses) and one
``<matcher>.tum`` (estimates; none is written for a role without any pose). A scan's timestamp is the ``stamp`` column of the dataset's
``scans.csv`` (set by ``tfloc import-bag``), else its row index there, else the order of first
appearance in ``estimates.csv``. Rows without a finite pose are left out and counted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tfloc.errors import DatasetError, TflocError
from tfloc.io.estimates import read_rows
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import read_scenario
from tfloc.io.text import csv_rows
from tfloc.io.tum import write_tum

NEEDED = ("dataset", "scan_id", "matcher", "true_x", "true_y", "true_theta", "init_x", "init_y",
          "init_theta", "est_x", "est_y", "est_theta")


@dataclass(frozen=True)
class Exported:
    """One written trajectory file: which dataset and role (``reference``, ``initial`` or a
    matcher name), how many poses, how many rows had none, and where the stamps came from."""

    path: Path | None  # None: no row had a pose, nothing written
    dataset: str
    role: str
    poses: int
    missing: int
    stamps: str  # "stamp" | "index" | "run order"


def _read_rows(path: Path) -> list[dict]:
    """The rows of an ``estimates.csv`` as strings (export needs no DataFrame), read and checked
    like every command reads them (:func:`tfloc.io.estimates.read_rows`), needing only the pose
    columns."""
    _, rows = read_rows(path, NEEDED)
    return [row for _, row in rows]


def _dataset_dirs(run_dir: Path) -> dict[str, Path]:
    """The run's datasets (name → directory) as ``run.json`` records them (none without one)."""
    try:
        return RunDir(run_dir).info().paths
    except TflocError:
        return {}


def find_dataset(name: str, run_dir: Path, root: Path | None) -> Path | None:
    """The directory of dataset ``name``: the run's record of it, a path, a directory of that name
    in the run directory or under ``root``, or any recorded directory whose scenario is named so."""
    recorded = _dataset_dirs(run_dir)
    cands = [*([recorded[name]] if name in recorded else []), Path(name), run_dir / name,
             *(d for d in recorded.values() if d.name == name)]
    if root is not None:
        cands.append(root / name)
    for c in cands:
        if (c / "scenario.json").is_file() and (c / "scans.csv").is_file():
            return c
    for d in recorded.values():  # a scenario.json whose "name" is the dataset's name
        try:
            if read_scenario(d).name == name:
                return d
        except TflocError:
            continue
    return None


def scan_stamps(dataset_dir: Path) -> tuple[dict[str, float], str]:
    """``scan_id → time (s)`` from ``scans.csv``: its ``stamp`` column, else the row index."""
    path = dataset_dir / "scans.csv"
    header, rows = csv_rows(path, DatasetError, "scans.csv file", ["scan_id"])
    has = "stamp" in header
    out: dict[str, float] = {}
    for k, (line, row) in enumerate(rows):
        s = (row.get("stamp") or "").strip() if has else ""
        try:
            out[row["scan_id"].strip()] = float(s) if s else float(k)
        except ValueError:
            raise DatasetError(f"{path}:{line}: stamp {s!r} is not a number") from None
    return out, "stamp" if has else "index"


def _pose(row: dict, prefix: str) -> np.ndarray | None:
    try:
        p = np.array([float(row[f"{prefix}_{k}"]) for k in ("x", "y", "theta")])
    except (TypeError, ValueError):
        return None
    return p if np.isfinite(p).all() else None


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_.+" else "_" for c in name) or "_"


def export_tum(run_dir: str | Path, out_dir: str | Path, datasets_root: Path | None = None) -> list[Exported]:
    """Write ``out_dir/<dataset>/{reference,initial,<matcher>}.tum`` for a run (``<dataset>``: the
    last part of the run's dataset name or path); returns what was written."""
    run_dir, out_dir = Path(run_dir), Path(out_dir)
    rows = _read_rows(RunDir(run_dir).estimates)
    by_ds: dict[str, list[dict]] = {}
    for r in rows:
        by_ds.setdefault(r["dataset"], []).append(r)
    written: list[Exported] = []
    for ds, drows in by_ds.items():
        d = find_dataset(ds, run_dir, datasets_root)
        if d is not None:
            stamps, how = scan_stamps(d)
        else:
            stamps, how = {}, "run order"
        for r in drows:  # scans unknown to the dataset: after the known ones, in run order
            if r["scan_id"] not in stamps:
                stamps[r["scan_id"]] = float(len(stamps)) if how != "stamp" else math.nan
        if any(math.isnan(v) for v in stamps.values()):
            bad = next(k for k, v in stamps.items() if math.isnan(v))
            raise DatasetError(f"{RunDir(run_dir).estimates}: scan {bad!r} of dataset {ds!r} is not in {d}/scans.csv")
        roles: dict[tuple[str, str], dict[str, np.ndarray | None]] = {}
        for r in drows:
            sid = r["scan_id"]
            roles.setdefault(("reference", ""), {})[sid] = _pose(r, "true")
            roles.setdefault(("initial", ""), {})[sid] = _pose(r, "init")
            roles.setdefault(("matcher", r["matcher"]), {})[sid] = _pose(r, "est")
        for (kind, matcher), poses in roles.items():
            ok = sorted((stamps[s], s) for s, p in poses.items() if p is not None)
            t = np.array([a for a, _ in ok])
            P = np.array([poses[s] for _, s in ok]).reshape(-1, 3)
            name = kind if not matcher else (_safe(matcher) if matcher not in ("reference", "initial")
                                             else f"matcher-{matcher}")
            path = write_tum(out_dir / _safe(Path(ds).name or ds) / f"{name}.tum", t, P) if ok else None
            written.append(Exported(path, ds, matcher or kind, len(ok), len(poses) - len(ok), how))
    return written
