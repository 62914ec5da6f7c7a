"""The timing measurements' files: where a typed row (:mod:`tfloc.core.rows.timing`) becomes text
and back, beside :mod:`tfloc.io.estimates` for the result rows.

``timing.csv`` (:class:`TimingRow`, numbers as ``%.4f``), and the scaling study's ``scaling.csv``
(:class:`ScanRow`), ``prep.csv`` (:class:`PrepRow`) and ``skips.csv`` (:class:`SkipRow`), numbers as
``%.6g``: the columns are the fields in order, NaN an empty cell, a status its text
(:meth:`~tfloc.core.result.Status.parse` reads it back; a preparation row not run is
``skipped``). :func:`write_rows` replaces a file atomically; :func:`read_rows` reads one strictly
(a missing column, a bad number or status is a :class:`~tfloc.errors.ResultsError` naming
``file:line``); :func:`rows_frame` is the table the evaluation reads, built from typed rows
whether they were just measured or read from a file.
"""

from __future__ import annotations

import csv
import math
from dataclasses import fields
from functools import cache
from pathlib import Path
from typing import Any, TypeVar, get_type_hints

import pandas as pd

from tfloc.core.result import Status
from tfloc.core.rows.timing import PrepRow, ScanRow, SkipRow, TimingRow
from tfloc.errors import ResultsError

from .atomic import replace_atomically
from .text import csv_rows

Row = TypeVar("Row", TimingRow, ScanRow, PrepRow, SkipRow)
#: each row type's file name and the format of its numbers (the files' format, unchanged)
FILES = {TimingRow: "timing.csv", ScanRow: "scaling.csv", PrepRow: "prep.csv", SkipRow: "skips.csv"}
FLOAT_FORMAT = {TimingRow: "%.4f", ScanRow: "%.6g", PrepRow: "%.6g", SkipRow: "%.6g"}
SKIPPED = "skipped"  # a PrepRow's status None


@cache
def _types(cls: type) -> dict[str, Any]:
    return get_type_hints(cls)


def columns(cls: type) -> list[str]:
    """The columns of ``cls``'s file: its fields, in order."""
    return [f.name for f in fields(cls)]


def _text(v: Any, float_format: str) -> str:
    if v is None:
        return SKIPPED
    if isinstance(v, float):
        return "" if math.isnan(v) else float_format % v
    return str(v)


def to_record(row: TimingRow | ScanRow | PrepRow | SkipRow) -> dict[str, str]:
    """A row as the text of its cells (module notes)."""
    fmt = FLOAT_FORMAT[type(row)]
    return {c: _text(getattr(row, c), fmt) for c in columns(type(row))}


def _value(kind: Any, text: str) -> Any:
    """The value of a cell of type ``kind``; ValueError naming what is wrong."""
    if kind is str:
        return text
    if kind is float:
        return float(text) if text.strip() else math.nan
    if kind is int:
        v = float(text)
        if not v.is_integer():
            raise ValueError(f"not an integer: {text[:40]!r}")
        return int(v)
    if text == SKIPPED and kind == (Status | None):
        return None
    status = Status.parse(text)
    if status is None:
        raise ValueError(f"unknown status {text[:40]!r}")
    return status


def from_record(cls: type[Row], record: dict[str, str]) -> Row:
    """The row of type ``cls`` written as ``record`` (cells as text); a ValueError names the
    column at fault."""
    kw = {}
    for c, kind in ((c, _types(cls)[c]) for c in columns(cls)):
        try:
            kw[c] = _value(kind, record.get(c) or "")
        except ValueError as exc:
            raise ValueError(f"column {c!r}: {exc}") from None
    return cls(**kw)


def write_rows(path: Path, rows: list[Row], cls: type[Row]) -> None:
    """``rows`` (of type ``cls``) into ``path`` with a header, atomically."""
    def write(fh) -> None:
        w = csv.DictWriter(fh, fieldnames=columns(cls), lineterminator="\n")
        w.writeheader()
        w.writerows(to_record(r) for r in rows)

    replace_atomically(Path(path), write)


def read_rows(path: Path, cls: type[Row]) -> list[Row]:
    """The rows of ``path`` as ``cls``; a missing file has none. A malformed one is a
    :class:`ResultsError` naming ``file:line``."""
    path = Path(path)
    if not path.exists():
        return []
    _, records = csv_rows(path, ResultsError, FILES[cls], columns(cls))
    out = []
    for line, record in records:
        if None in record or any(v is None for v in record.values()):
            raise ResultsError(f"{path}:{line}: expected {len(columns(cls))} fields")
        try:
            out.append(from_record(cls, record))
        except ValueError as exc:
            raise ResultsError(f"{path}:{line}: {exc}") from None
    return out


def rows_frame(rows: list[Row], cls: type[Row]) -> pd.DataFrame:
    """Rows as the evaluation's table: one column per field (a status as its text, ``None``
    as ``skipped``), numbers as numbers."""
    cols = columns(cls)
    records = [{c: (SKIPPED if (v := getattr(r, c)) is None else str(v) if isinstance(v, Status) else v)
                for c in cols} for r in rows]
    return pd.DataFrame(records, columns=cols)
