"""``estimates.csv``: the append-only results file of a run, safe to resume after a kill -9."""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any

import pandas as pd

COLUMNS = ["dataset", "scan_id", "group", "matcher",
           "true_x", "true_y", "true_theta", "init_x", "init_y", "init_theta",
           "est_x", "est_y", "est_theta", "dist_err_m", "orient_err_rad",
           "init_dist_err_m", "init_orient_err_rad", "runtime_s", "cpu_s", "converged", "iterations",
           "evaluations", "status", "outcome", "score_est", "score_true", "info"]
KEY = ("dataset", "scan_id", "matcher")


def repair(path: Path) -> None:
    """Drop a torn last line (a row cut off by a kill mid-write)."""
    if not path.exists() or path.stat().st_size == 0:
        return
    with path.open("rb+") as fh:
        data = fh.read()
        if not data.endswith(b"\n"):
            fh.truncate(data.rfind(b"\n") + 1)


def done_keys(path: Path) -> set[tuple[str, str, str]]:
    """Keys (dataset, scan_id, matcher) already in the results file."""
    repair(path)
    if not path.exists() or path.stat().st_size == 0:
        return set()
    with path.open(newline="") as fh:
        return {tuple(r[k] for k in KEY) for r in csv.DictReader(fh)}


class ResultWriter:
    """Appends one row per finished task and makes it durable at once (flush + fsync)."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        repair(self.path)
        new = not self.path.exists() or self.path.stat().st_size == 0
        header = COLUMNS if new else _header(self.path)  # resuming an older run keeps its columns
        self._fh = self.path.open("a", newline="")
        self._w = csv.DictWriter(self._fh, fieldnames=header, extrasaction="ignore")
        if new:
            self._w.writeheader()
            self._sync()

    def _sync(self) -> None:
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def write(self, row: dict[str, Any]) -> None:
        self._w.writerow({k: _fmt(v) for k, v in row.items()})
        self._sync()

    def close(self) -> None:
        self._fh.close()

    def __enter__(self) -> ResultWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _header(path: Path) -> list[str]:
    with path.open(newline="") as fh:
        return next(csv.reader(fh))


def _fmt(v: Any) -> Any:
    return f"{v:.9g}" if isinstance(v, float) else v


def read_estimates(run_dir: str | Path) -> pd.DataFrame:
    """The results of a run as a DataFrame (one row per (dataset, scan, matcher))."""
    path = Path(run_dir) / "estimates.csv"
    repair(path)
    return pd.read_csv(path, dtype={"scan_id": str, "group": str, "dataset": str, "matcher": str,
                                    "status": str, "outcome": str, "info": str})
