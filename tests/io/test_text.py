"""The one text reader: UTF-8 with or without a BOM, LF or CRLF, gzip; anything else one line."""

from __future__ import annotations

import codecs
import gzip
import shutil
from pathlib import Path

import pytest
from _paths import ROOT

from tfloc.errors import DatasetError, MapFormatError
from tfloc.io.geojson import read_vector_map
from tfloc.io.scenario import read_scans, read_scenario
from tfloc.io.text import read_text


def test_bom_crlf_and_gzip_read_alike(tmp_path: Path) -> None:
    plain = "a,b\n1,2\n"
    variants = {"bom-crlf.txt": codecs.BOM_UTF8 + plain.replace("\n", "\r\n").encode(),
                "plain.txt": plain.encode(), "zipped.txt.gz": gzip.compress(plain.encode())}
    for name, data in variants.items():
        (tmp_path / name).write_bytes(data)
        assert read_text(tmp_path / name, DatasetError, "file") == plain


@pytest.mark.parametrize(("data", "message"), [
    ("a,b\n".encode("utf-16"), "UTF-16/32 text; save the file as UTF-8"),
    (b"\x89PNG\r\n\x1a\n\x00\x00", "binary data"),
    (b"ok\n\xff\xfe bad", ":2: not UTF-8 text"),
    (b"\x1f\x8b\x08\x00broken", "damaged gzip data"),
])
def test_what_is_not_text_is_one_line_naming_the_file(tmp_path: Path, data: bytes, message: str) -> None:
    (tmp_path / "f").write_bytes(data)
    with pytest.raises(DatasetError, match=message) as err:
        read_text(tmp_path / "f", DatasetError, "file")
    assert str(err.value).startswith(str(tmp_path / "f")) and "\n" not in str(err.value)


def test_missing_file_and_directory(tmp_path: Path) -> None:
    with pytest.raises(MapFormatError, match="no such map file"):
        read_vector_map(tmp_path / "nope.geojson")
    with pytest.raises(MapFormatError, match="is a directory"):
        read_vector_map(tmp_path)


def test_a_spreadsheet_saved_scans_csv_localizes(tmp_path: Path) -> None:
    """A scans.csv saved with a BOM and CRLF line ends (Excel on Windows) reads like the original."""
    src = ROOT / "data" / "scenarios" / "detail-1"
    dst = tmp_path / "detail-1"
    dst.mkdir()
    shutil.copy(src / "scenario.json", dst)
    text = (src / "scans.csv").read_text()
    (dst / "scans.csv").write_bytes(codecs.BOM_UTF8 + text.replace("\n", "\r\n").encode())
    doc = (dst / "scenario.json").read_text().replace('"map": "', f'"map": "{src.resolve()}/')
    (dst / "scenario.json").write_text(doc)
    a, b = read_scans(read_scenario(src)), read_scans(read_scenario(dst))
    assert [s.scan_id for s in a] == [s.scan_id for s in b]
    assert all((x.ranges == y.ranges).all() and x.initial == y.initial for x, y in zip(a, b, strict=True))
