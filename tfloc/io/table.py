"""The one codec of a run directory's tables: a row type's file as text and back.

A :class:`Table` names a file and its row type (a frozen dataclass of :mod:`tfloc.core.rows`):
the columns are the fields in order, each cell typed by its field: ``str``; ``int``; ``float``
(written as the table's format, NaN an empty cell); ``bool`` (``True``/``False``); a
:class:`~tfloc.core.result.Status` (its text; ``None`` written ``skipped``). A file ending in
``.gz`` is gzip-compressed, its header stamped with no time (the same rows give the same bytes).

* :func:`write` replaces a file atomically from rows or from a table of exactly the row type's
  columns (a column missing or extra is a :class:`~tfloc.errors.ResultsError`: a producer that
  drifts from its type is caught where it writes);
* :func:`read_rows` gives the rows as the row type, :func:`read_frame` a table with every column
  of its type (numbers as numbers, text as text, ``""`` for an empty text cell): both read
  strictly, a missing column, a bad number, boolean or status a one-line
  :class:`~tfloc.errors.ResultsError` naming ``file:line``; a missing file has no rows. A column
  whose field has a default may be missing from an older file (it reads as the default).
* :func:`frame_of` is the same table built from rows in memory.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import MISSING, dataclass, fields
from functools import cache
from pathlib import Path
from typing import Any, get_args, get_type_hints

import numpy as np
import pandas as pd

from tfloc.core.result import Status
from tfloc.errors import ResultsError

from .atomic import sync_dir
from .text import read_text

SKIPPED = "skipped"  # a ``Status | None`` cell that is None
_TRUE, _FALSE = frozenset({"true", "1", "1.0"}), frozenset({"false", "0", "0.0"})


@dataclass(frozen=True)
class Table:
    """A file of a run directory (``name``) and its row type; numbers written as
    ``float_format``; ``what`` it holds, for messages."""

    name: str
    row: type
    what: str
    float_format: str = "%.6g"

    @property
    def columns(self) -> list[str]:
        return columns(self.row)


@cache
def _kinds(cls: type) -> dict[str, Any]:
    return get_type_hints(cls)


def columns(cls: type) -> list[str]:
    """The columns of ``cls``'s file: its fields, in order."""
    return [f.name for f in fields(cls)]


@cache
def _defaults(cls: type) -> dict[str, Any]:
    return {f.name: f.default for f in fields(cls) if f.default is not MISSING}


def _text(v: Any, kind: Any, float_format: str) -> str:
    if v is None:
        return SKIPPED if kind == (Status | None) else ""
    if isinstance(v, bool | np.bool_):
        return str(bool(v))
    if isinstance(v, float | np.floating):
        return "" if math.isnan(v) else float_format % v
    return str(v)


def _optional(kind: Any) -> Any:
    """``X`` for a kind ``X | None`` (but a status's, whose None is ``skipped``), else None."""
    args = get_args(kind)
    if len(args) == 2 and type(None) in args and Status not in args:
        return next(a for a in args if a is not type(None))
    return None


def _value(kind: Any, text: str) -> Any:
    """The value of one cell of type ``kind``; ValueError naming what is wrong."""
    if (inner := _optional(kind)) is not None:
        return None if not text.strip() else _value(inner, text)
    if kind is str:
        return text
    if kind is float:
        try:
            return float(text) if text.strip() else math.nan
        except ValueError:
            raise ValueError(f"not a number: {text[:40]!r}") from None
    if kind is int:
        v = float(text)
        if not v.is_integer():
            raise ValueError(f"not an integer: {text[:40]!r}")
        return int(v)
    if kind is bool:
        t = text.strip().lower()
        if t not in _TRUE | _FALSE:
            raise ValueError(f"not True or False: {text[:40]!r}")
        return t in _TRUE
    if text == SKIPPED and kind == (Status | None):
        return None
    status = Status.parse(text)
    if status is None:
        raise ValueError(f"unknown status {text[:40]!r}")
    return status


def to_record(row: Any, float_format: str = "%.6g") -> dict[str, str]:
    """A row as the text of its cells (module notes)."""
    kinds = _kinds(type(row))
    return {c: _text(getattr(row, c), kinds[c], float_format) for c in columns(type(row))}


def from_record(cls: type, record: dict[str, str]) -> Any:
    """The row of type ``cls`` written as ``record`` (cells as text; a column with a default may
    be absent); a ValueError names the column at fault."""
    kw, kinds, defaults = {}, _kinds(cls), _defaults(cls)
    for c in columns(cls):
        if c not in record and c in defaults:
            continue
        try:
            kw[c] = _value(kinds[c], record.get(c) or "")
        except ValueError as exc:
            raise ValueError(f"column {c!r}: {exc}") from None
    return cls(**kw)


def _frame_text(df: pd.DataFrame, table: Table) -> pd.DataFrame:
    """``df`` (exactly the table's columns, any order) in column order with every cell as its
    text (the codec's, for numbers the table's format)."""
    cols = table.columns
    extra, missing = sorted(set(df.columns) - set(cols)), [c for c in cols if c not in df.columns]
    if extra or missing:
        raise ResultsError(f"{table.name}: the table to write is not a {table.row.__name__} table "
                           f"(missing {', '.join(missing) or 'nothing'}; extra {', '.join(extra) or 'nothing'})")
    kinds = _kinds(table.row)
    out = {}
    for c in cols:
        kind, v = kinds[c], df[c]
        if kind is float:
            num = pd.to_numeric(v, errors="coerce").astype(float)
            out[c] = [("" if math.isnan(x) else table.float_format % x) for x in num.to_numpy()]
        else:
            out[c] = [_text(x if not (isinstance(x, float) and math.isnan(x) and kind is not float) else None,
                            kind, table.float_format) for x in v.to_numpy(dtype=object)]
    return pd.DataFrame(out, columns=cols)


def write(path: Path, table: Table, rows: Iterable[Any] | pd.DataFrame) -> Path:
    """``rows`` (of the table's row type, or a table of exactly its columns) into ``path``,
    atomically, with a header; returns ``path``."""
    path = Path(path)
    df = rows if isinstance(rows, pd.DataFrame) else frame_of(list(rows), table.row)
    text = _frame_text(df, table)
    tmp = path.with_name(path.name + ".tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        compression = {"method": "gzip", "mtime": 0} if path.suffix == ".gz" else None
        text.to_csv(tmp, index=False, lineterminator="\n", compression=compression)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
        sync_dir(path.parent)
    except OSError as exc:
        raise ResultsError(f"{path}: cannot write ({exc.strerror or exc})") from None
    return path


def _read_text_frame(path: Path, table: Table) -> pd.DataFrame:
    """The cells of a table file as text, its columns checked (a missing column with a default
    filled in)."""
    text = read_text(path, ResultsError, f"{table.what} ({table.name})")
    try:
        raw = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        if isinstance(exc, pd.errors.EmptyDataError):
            raise ResultsError(f"{path}:1: empty file, expected the header {','.join(table.columns)}") from None
        raise ResultsError(f"{path}: unreadable CSV ({str(exc).splitlines()[0]})") from None
    for line, fields_ in enumerate(csv.reader(io.StringIO(text)), start=1):  # pandas pads a short row
        if len(fields_) != len(raw.columns) and fields_:
            raise ResultsError(f"{path}:{line}: {len(fields_)} fields, expected {len(raw.columns)}")
    defaults = _defaults(table.row)
    missing = [c for c in table.columns if c not in raw.columns and c not in defaults]
    if missing:
        raise ResultsError(f"{path}:1: header lacks column(s) {', '.join(missing)} "
                           f"(not a {table.row.__name__} table)")
    for c in table.columns:
        if c not in raw.columns:
            raw[c] = _text(defaults[c], _kinds(table.row)[c], table.float_format)
    return raw[table.columns]


def read_frame(path: Path, table: Table) -> pd.DataFrame:
    """The table in ``path`` with every column as its type (module notes); a missing file gives
    an empty table of the columns."""
    path = Path(path)
    kinds = _kinds(table.row)
    if not path.exists():
        return frame_of([], table.row)
    raw = _read_text_frame(path, table)
    out = {}
    for c in table.columns:
        kind, cells = kinds[c], raw[c]
        if kind is str:
            out[c] = cells.astype(str)
            continue
        if kind in (float, int):
            stripped = cells.str.strip()
            num = pd.to_numeric(stripped.where(stripped != "", None), errors="coerce")
            bad = num.isna() & (stripped != "") & ~stripped.str.lower().isin(["nan", "-nan", "+nan"])
            if kind is int:
                bad |= num.isna() | (num.notna() & (num % 1 != 0))
            if bad.any():
                i = int(np.flatnonzero(bad.to_numpy())[0])
                what = "an integer" if kind is int else "a number"
                raise ResultsError(f"{path}:{i + 2}: column {c!r}: not {what}: {cells.iloc[i][:40]!r}")
            out[c] = num.astype(int if kind is int else float)
            continue
        try:
            out[c] = pd.Series([_value(kind, t) for t in cells], dtype=object)
        except ValueError as exc:
            i = next(i for i, t in enumerate(cells) if _fails(kind, t))
            raise ResultsError(f"{path}:{i + 2}: column {c!r}: {exc}") from None
        if kind is bool:
            out[c] = out[c].astype(bool)
        elif kind in (Status, Status | None):
            out[c] = cells.astype(str)
    return pd.DataFrame(out, columns=table.columns)


def _fails(kind: Any, text: str) -> bool:
    try:
        _value(kind, text)
    except ValueError:
        return True
    return False


def read_rows(path: Path, table: Table) -> list[Any]:
    """The rows of ``path`` as the table's row type; a missing file has none (module notes)."""
    path = Path(path)
    if not path.exists():
        return []
    raw = _read_text_frame(path, table)
    out = []
    for i, record in enumerate(raw.to_dict("records")):
        try:
            out.append(from_record(table.row, record))
        except ValueError as exc:
            raise ResultsError(f"{path}:{i + 2}: {exc}") from None
    return out


def frame_of(rows: Sequence[Any], cls: type) -> pd.DataFrame:
    """Rows in memory as :func:`read_frame` gives them: one column per field (a status as its
    text, ``None`` as ``skipped``), numbers as numbers."""
    cols = columns(cls)
    kinds = _kinds(cls)
    records = [{c: (SKIPPED if (v := getattr(r, c)) is None and kinds[c] == (Status | None)
                    else str(v) if isinstance(v, Status) else v) for c in cols} for r in rows]
    df = pd.DataFrame(records, columns=cols)
    for c in cols:
        if kinds[c] is float:
            df[c] = df[c].astype(float)
        elif kinds[c] is str and not len(df):
            df[c] = df[c].astype(object)
    return df
