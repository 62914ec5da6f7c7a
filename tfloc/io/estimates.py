"""``estimates.csv``: the append-only results file of a run, safe to resume after a kill -9.

The edge where a :class:`~tfloc.core.result.ResultRow` becomes text and back (:func:`to_record`,
:func:`from_record`); :func:`result_row` is the one builder of a row. One reader for every
command (``report``, ``export``, ``real-note``, resume): :func:`read_rows` reads strictly through
:mod:`tfloc.io.text`; a malformed file is a :class:`~tfloc.errors.ResultsError` naming
``file:line``. :func:`read_estimates` (a file) and :func:`rows_frame` (rows in memory) give the
same table for the evaluation. A row's ``status`` is ``ok``, ``failed`` (the matcher declined or
gave no finite pose), ``invalid:<reason>`` (the data poses no problem, e.g. the initial pose lies
outside the map), ``timeout`` or ``error:<message>`` (the matcher raised).
"""

from __future__ import annotations

import csv
import errno
import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from tfloc.core.result import COLUMNS, OK, ResultRow, Status, StatusKind, kind_of_status
from tfloc.errors import ResultsError

from .atomic import replace_atomically
from .text import csv_rows

KEY = ("dataset", "scan_id", "matcher")
#: the columns every reader needs (older runs may lack the others)
REQUIRED = ("dataset", "scan_id", "group", "matcher", "true_x", "true_y", "true_theta", "init_x",
            "init_y", "init_theta", "est_x", "est_y", "est_theta", "dist_err_m", "orient_err_rad",
            "init_dist_err_m", "init_orient_err_rad", "runtime_s", "converged", "iterations",
            "evaluations", "status", "outcome")
TEXT = ("dataset", "scan_id", "group", "matcher", "status", "outcome", "info")
STATUS_KINDS = tuple(k.value for k in StatusKind)
#: the columns whose values are numbers (the rest are text; ``status`` and ``info`` are parsed)
NUMERIC = tuple(c for c in COLUMNS if c not in TEXT)
INTEGER = ("converged", "iterations", "evaluations")


def pose_fields(prefix: str, pose) -> dict[str, Any]:
    """A pose (:class:`~tfloc.core.pose.Pose` or None) as the row's ``<prefix>_x/y/theta``
    fields (``None`` each when the pose is)."""
    if pose is None:
        return {f"{prefix}_x": None, f"{prefix}_y": None, f"{prefix}_theta": None}
    return {f"{prefix}_x": pose.x, f"{prefix}_y": pose.y, f"{prefix}_theta": pose.theta}


def result_row(dataset: str, matcher: str, scan_id: str, group: str = "", *, true=None, init=None,
               est=None, estimate=None, status: Status | str = OK, wall_s: float | None = None,
               cpu_s: float | None = None, info: dict | None = None) -> ResultRow:
    """The one builder of a result row: identity, the true, initial and estimated poses
    (:class:`~tfloc.core.pose.Pose` or ``None``), their errors where the truth is known
    (:meth:`~tfloc.core.pose.Pose.error_to`), the times (seconds), the estimate's counters (an
    :class:`~tfloc.core.problem.Estimate`, if any), ``status`` and ``info``. ``outcome`` and
    ``score_*`` are the caller's (they need the thresholds and the matcher)."""
    if not isinstance(status, Status):
        status = Status.parse(status) or Status.of(StatusKind.ERROR, f"unknown status {status!r}")
    row: dict[str, Any] = dict(dataset=dataset, scan_id=scan_id, group=group, matcher=matcher, status=status,
                               runtime_s=wall_s, cpu_s=cpu_s, info=info, **pose_fields("true", true),
                               **pose_fields("init", init), **pose_fields("est", est))
    if true is not None and init is not None:
        row["init_dist_err_m"], row["init_orient_err_rad"] = init.error_to(true)
    if true is not None and est is not None:
        row["dist_err_m"], row["orient_err_rad"] = est.error_to(true)
    if estimate is not None:
        row.update(converged=int(bool(estimate.converged)), iterations=estimate.iterations,
                   evaluations=estimate.evaluations)
    return ResultRow(**row)


def status_kind(status: str) -> str | None:
    """``ok``, ``failed``, ``invalid``, ``timeout`` or ``error`` (``invalid:…``/``error:…`` carry a
    message); ``None`` for anything else (:meth:`tfloc.core.result.Status.parse`)."""
    return kind_of_status(status)


def status_kinds(status: pd.Series) -> pd.Series:
    """:func:`status_kind` of a column of statuses (a report's rows)."""
    return status.astype(str).map(kind_of_status)


def to_record(row: ResultRow) -> dict[str, str]:
    """A row as the text of its ``estimates.csv`` cells (numbers to 9 significant digits,
    ``None`` an empty cell, ``info`` compact JSON)."""
    out = {}
    for c in COLUMNS:
        v = getattr(row, c)
        if c == "info":
            out[c] = "" if v is None else json.dumps(v, default=str, separators=(",", ":"))
        elif c == "status":
            out[c] = str(v)
        else:
            out[c] = "" if v is None else _fmt(v)
    return out


def _number(text: str, integer: bool) -> float | int | None:
    text = text.strip()
    if not text:
        return None
    v = float(text)
    return int(v) if integer and v.is_integer() else v


def from_record(record: dict[str, str]) -> ResultRow:
    """The row written as ``record`` (cells as text; a column the file lacks is empty)."""
    kw: dict[str, Any] = {}
    for c in COLUMNS:
        text = record.get(c) or ""
        if c == "status":
            kw[c] = Status.parse(text) or OK
        elif c == "info":
            kw[c] = json.loads(text) if text.strip() else None
        elif c in TEXT:
            kw[c] = text
        else:
            kw[c] = _number(text, c in INTEGER)
    return ResultRow(**kw)


def repair(path: Path) -> None:
    """Drop a torn last line (a row cut off by a kill mid-write)."""
    if not path.exists() or path.stat().st_size == 0:
        return
    with path.open("rb+") as fh:
        data = fh.read()
        if not data.endswith(b"\n"):
            fh.truncate(data.rfind(b"\n") + 1)


def read_rows(path: Path, required: tuple[str, ...] = REQUIRED) -> tuple[list[str], list[tuple[int, dict]]]:
    """The header and the rows ``(line, row)`` of a results file, checked: every row has the
    header's fields, a known ``status`` and a key (dataset, scan_id, matcher) no other row has."""
    header, rows = csv_rows(path, ResultsError, "results file (estimates.csv)", (*KEY, *required))
    out, seen = [], {}
    for line, row in rows:
        extra, missing = row.pop(None, None) or (), sum(v is None for v in row.values())
        if extra or missing:
            raise ResultsError(f"{path}:{line}: {len(header) + len(extra) - missing} fields, expected {len(header)}")
        key = tuple(row[k] for k in KEY)
        if not all(key):
            raise ResultsError(f"{path}:{line}: empty {', '.join(k for k, v in zip(KEY, key, strict=True) if not v)}")
        if key in seen:
            raise ResultsError(f"{path}:{line}: a second row for {'/'.join(key)} (first at line {seen[key]})")
        seen[key] = line
        if "status" in row and status_kind(row["status"]) is None:
            raise ResultsError(f"{path}:{line}: unknown status {row['status'][:40]!r} "
                               "(ok, failed, invalid:…, timeout or error:…)")
        out.append((line, row))
    return header, out


def done_keys(path: Path, redo: tuple[str, ...] = ()) -> set[tuple[str, str, str]]:
    """Keys (dataset, scan_id, matcher) already in the results file, but for those whose status
    kind is in ``redo``."""
    repair(path)
    if not path.exists() or path.stat().st_size == 0:
        return set()
    _, rows = read_rows(path)
    return {tuple(r[k] for k in KEY) for _, r in rows if status_kind(r["status"]) not in redo}


def status_counts(path: Path) -> dict[str, int]:
    """Rows of the results file per status kind (:data:`STATUS_KINDS`, all present)."""
    counts = dict.fromkeys(STATUS_KINDS, 0)
    if path.exists() and path.stat().st_size:
        for _, r in read_rows(path)[1]:
            counts[status_kind(r["status"])] += 1
    return counts


def drop_rows(path: Path, keep: set[tuple[str, str, str]]) -> int:
    """Rewrite the results file with only the rows whose key is in ``keep``, atomically (a kill
    leaves the old file or the new one, never a mix); returns how many rows were dropped."""
    header, rows = read_rows(path)
    kept = [r for _, r in rows if tuple(r[k] for k in KEY) in keep]
    if len(kept) == len(rows):
        return 0
    def write(fh) -> None:
        w = csv.DictWriter(fh, fieldnames=header, extrasaction="ignore")
        w.writeheader()
        w.writerows(kept)

    replace_atomically(path, write, "cannot rewrite; the file is unchanged")
    return len(rows) - len(kept)


class ResultWriter:
    """Appends one row per finished task and makes it durable at once (flush + fsync).

    A failing write (a full disk, a read-only directory) raises :class:`ResultsError`; the rows
    written before stay intact (a torn last line is dropped when the run is resumed).
    """

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.rows = 0
        try:
            repair(self.path)
            new = not self.path.exists() or self.path.stat().st_size == 0
            header = COLUMNS if new else _header(self.path)  # resuming an older run keeps its columns
            self._fh = self.path.open("a", newline="")
            self._w = csv.DictWriter(self._fh, fieldnames=header, extrasaction="ignore")
            if new:
                self._w.writeheader()
                self._sync()
        except OSError as exc:
            raise self._failed(exc) from None

    def _failed(self, exc: OSError) -> ResultsError:
        why = "the disk is full" if exc.errno == errno.ENOSPC else (exc.strerror or str(exc))
        return ResultsError(f"{self.path}: cannot write ({why}); the rows written before are kept: "
                            "free the space or fix the permissions, then run the same command to resume")

    def _sync(self) -> None:
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def write(self, row: ResultRow) -> None:
        try:
            self._w.writerow(to_record(row))
            self._sync()
        except OSError as exc:
            raise self._failed(exc) from None
        self.rows += 1

    def close(self) -> None:
        try:
            self._fh.close()
        except OSError:
            pass

    def __enter__(self) -> ResultWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _header(path: Path) -> list[str]:
    with path.open(newline="") as fh:
        return next(csv.reader(fh))


def _fmt(v: Any) -> Any:
    return f"{v:.9g}" if isinstance(v, float) else v


def read_estimates(run_dir: str | Path, required: tuple[str, ...] = REQUIRED) -> pd.DataFrame:
    """The results of a run as a DataFrame (one row per (dataset, scan, matcher)): text columns
    as strings (empty: ``""``), the others as numbers (empty: NaN). A malformed file raises
    :class:`ResultsError` naming ``file:line``."""
    path = Path(run_dir) / "estimates.csv"
    if Path(run_dir).is_dir():
        repair(path)
    header, rows = read_rows(path, required)
    return _frame(header, [r for _, r in rows], [line for line, _ in rows], path)


def rows_frame(rows: list[ResultRow]) -> pd.DataFrame:
    """Rows in memory as the table :func:`read_estimates` gives for the same rows written."""
    return _frame(COLUMNS, [to_record(r) for r in rows], list(range(2, len(rows) + 2)), Path("(rows)"))


def _frame(header: list[str], records: list[dict], line_numbers: list[int], path: Path) -> pd.DataFrame:
    df = pd.DataFrame(records, columns=header, dtype=object)
    lines = np.array(line_numbers, dtype=int)
    for c in header:
        if c in TEXT:
            df[c] = df[c].astype(str)
            continue
        text = df[c].astype(str).str.strip()
        num = pd.to_numeric(text.where(text != "", None), errors="coerce")
        bad = np.flatnonzero(num.isna().to_numpy() & (text != "").to_numpy()
                             & ~text.str.lower().isin(["nan", "-nan", "+nan"]).to_numpy())
        if bad.size:
            raise ResultsError(f"{path}:{lines[bad[0]]}: column {c!r} is not a number: {text.iloc[bad[0]][:40]!r}")
        df[c] = num.astype(float) if num.dtype == object else num
    return df
