"""The one codec of a run directory's tables: typed rows round trip, every committed table file
of a declared type is read and written again byte for byte, a table that drifts from its row
type is refused where it is written, and a malformed file is named at its line."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

from tfloc.core.result import Status, StatusKind
from tfloc.core.rows.timing import MAP, PrepRow, ScanRow, SkipRow, TimingRow
from tfloc.errors import ResultsError
from tfloc.io import tables
from tfloc.io.table import (
    Table,
    columns,
    frame_of,
    from_record,
    read_frame,
    read_rows,
    to_record,
    write,
)

FILES = {tables.TIMING.row: tables.TIMING, tables.SCALING.row: tables.SCALING, tables.PREP.row: tables.PREP,
         tables.SKIPS.row: tables.SKIPS}
#: every table file the store declares (the guard's references are files of their own)
DECLARED = [t for t in vars(tables).values() if isinstance(t, Table)]

ROOT = Path(__file__).resolve().parents[2]

ROWS = {
    TimingRow: [TimingRow("office-pool", "d1-a1-058", "d1-a1", "tf-plus", 0, 1.2345, 1.3),
                TimingRow("office-pool", "0007", "d1-a1", "o3d-icp", 1, 20.0, math.nan)],
    ScanRow: [ScanRow("tf-plus", "area", "grid", "2x2", 1293.6, 4, 181, 180.0, "a000", "0-1 m", 0.510468, 0,
                      1.25, 0.0, 1.3, 0.001, 0.02, 1, Status()),
              ScanRow("csm-corr", "beams", "vector", "361 (180°/0.5°)", 361.0, 1, 361, 180.0, "b001", "1-2 m",
                      1.5, 1, math.nan, 0.0, math.nan, math.nan, math.nan, 0,
                      Status.of(StatusKind.ERROR, "ValueError: bad, very bad\nindeed"))],
    PrepRow: [PrepRow(MAP, "grid", 16, 5174.4, 2069000, 0, 0.5, 0.51, 80.0, 90.5, Status()),
              PrepRow("karto", "grid", 64, 20698.0, 0, 0, math.nan, math.nan, math.nan, math.nan, None),
              PrepRow("gicp", "vector", 1, 323.4, 0, 81, math.nan, math.nan, math.nan, math.nan,
                      Status.of(StatusKind.ERROR, "MemoryError"))],
    SkipRow: [SkipRow("area", "grid", "8x8", 20698.0, "karto", "median 300 ms > 250 ms at 4x4")],
}


def _same(a, b) -> bool:
    """Rows equal, NaN equal to NaN."""
    return type(a) is type(b) and all(
        (x != x and y != y) or x == y for x, y in ((getattr(a, c), getattr(b, c)) for c in columns(type(a))))


@pytest.mark.parametrize("cls", list(ROWS), ids=lambda c: c.__name__)
def test_typed_rows_round_trip_through_csv(cls, tmp_path):
    rows = ROWS[cls]
    table = FILES[cls]
    path = tmp_path / table.name
    write(path, table, rows)
    back = read_rows(path, table)
    assert len(back) == len(rows) and all(_same(a, b) for a, b in zip(rows, back, strict=True))
    assert path.read_text().splitlines()[0] == ",".join(columns(cls))
    assert all(_same(from_record(cls, to_record(r, table.float_format)), r) for r in rows)
    frame = frame_of(back, cls)
    assert list(frame.columns) == columns(cls) and len(frame) == len(rows)
    again = tmp_path / ("again-" + table.name)
    write(again, table, read_frame(path, table))  # a typed table writes the same text as its rows
    assert again.read_text() == path.read_text()


def _rec(row, cls=None):
    return to_record(row, FILES[type(row)].float_format)


def test_the_cells_as_written():
    to_record = _rec  # noqa: N806 - each table's own number format
    scan = to_record(ROWS[ScanRow][1])
    assert scan["size"] == "361" and scan["cpu_ms"] == "" and scan["status"].startswith("error:ValueError: bad")
    assert "\n" not in scan["status"]
    assert to_record(ROWS[PrepRow][1])["status"] == "skipped"
    assert to_record(ROWS[PrepRow][0])["cells"] == "2069000" and to_record(ROWS[PrepRow][0])["size"] == "5174.4"
    assert to_record(TimingRow("d", "s", "g", "m", 0, 1.23456, 2.0))["cpu_ms"] == "1.2346"  # timing.csv: %.4f
    third = replace(ROWS[ScanRow][0], init_dist_m=1 / 3, cpu_ms=12345678.9)          # the study's: %.6g
    assert (to_record(third)["init_dist_m"], to_record(third)["cpu_ms"]) == ("0.333333", "1.23457e+07")
    assert to_record(replace(ROWS[PrepRow][0], prep_cpu_s=2 / 3))["prep_cpu_s"] == "0.666667"
    assert to_record(replace(ROWS[SkipRow][0], size=1 / 3))["size"] == "0.333333"
    assert from_record(PrepRow, to_record(ROWS[PrepRow][1])).status is None
    assert from_record(ScanRow, to_record(ROWS[ScanRow][1])).status.kind is StatusKind.ERROR


def test_the_tables_the_evaluation_reads():
    scans = frame_of(ROWS[ScanRow], ScanRow)
    assert scans["tiles"].dtype.kind == "i" and scans["cpu_ms"].dtype.kind == "f"
    assert list(scans["status"]) == ["ok", str(ROWS[ScanRow][1].status)]
    assert list(frame_of(ROWS[PrepRow], PrepRow)["status"]) == ["ok", "skipped", "error:MemoryError"]
    assert list(frame_of([], SkipRow).columns) == columns(SkipRow)


def _committed() -> list[tuple[Path, Table]]:
    """Every committed table file of a run directory, with its declared type (a scaling study's
    ``summary.csv``-named files excepted: the guard's references live in results/reference/)."""
    out = []
    for t in DECLARED:
        if t in (tables.GUARD, tables.GUARD_TRACKING):
            out += [(p, t) for p in (ROOT / "results" / "reference").glob(t.name)]
            continue
        out += [(p, t) for p in sorted((ROOT / "results").rglob(t.name)) if "reference" not in p.parts
                and "site" not in p.parts]
    return out


@pytest.mark.bitwise
@pytest.mark.parametrize("path, table", _committed(), ids=lambda x: str(x.relative_to(ROOT)) if isinstance(x, Path) else "")
def test_committed_files_keep_their_format(path, table, tmp_path):
    """A committed table file read as typed rows and written again is the same text, byte for
    byte: the store's one codec is the format every committed table has."""
    out = tmp_path / path.name
    write(out, table, read_rows(path, table))
    assert out.read_bytes() == path.read_bytes()


def test_a_table_that_drifts_from_its_row_type_is_refused_where_it_is_written(tmp_path):
    df = frame_of(ROWS[TimingRow], TimingRow)
    with pytest.raises(ResultsError, match="not a TimingRow table .missing wall_ms; extra extra"):
        write(tmp_path / "timing.csv", tables.TIMING, df.drop(columns="wall_ms").assign(extra=1))


@pytest.mark.parametrize("line, message", [
    ("tf-plus,grid,1,323.4,0,81,0.1,0.1,1,1,maybe", "prep.csv:3: column 'status': unknown status 'maybe'"),
    ("tf-plus,grid,1.5,323.4,0,81,0.1,0.1,1,1,ok", "prep.csv:3: column 'tiles': not an integer"),
    ("tf-plus,grid,1,lots,0,81,0.1,0.1,1,1,ok", "prep.csv:3: column 'size'"),
    ("tf-plus,grid,1,323.4,0,81,0.1,0.1,1,ok", "prep.csv:3: 10 fields, expected 11"),
])
def test_a_malformed_file_is_named_at_its_line(tmp_path, line, message):
    path = tmp_path / "prep.csv"
    good = ",".join(_rec(ROWS[PrepRow][0]).values())
    path.write_text(",".join(columns(PrepRow)) + "\n" + good + "\n" + line + "\n")
    for read in (read_rows, read_frame):
        with pytest.raises(ResultsError, match=message.replace("(", r"\(")):
            read(path, tables.PREP)
    path.write_text("matcher,kind\n")
    with pytest.raises(ResultsError, match="prep.csv:1: header lacks"):
        read_rows(path, tables.PREP)
    assert read_rows(tmp_path / "none.csv", tables.PREP) == []
