"""Reading the project's text files, one way for every format: what users have is accepted.

UTF-8 with or without a byte-order mark (what spreadsheets on Windows write), LF or CRLF line
ends, optionally gzip-compressed. Anything else (a missing file, a directory, UTF-16, binary
data, bytes that are not UTF-8 where UTF-8 is required) raises the caller's error type with one
line naming the file. Parsers report their syntax errors the same way (:func:`parse_text`).
"""

from __future__ import annotations

import codecs
import csv
import gzip
import io
import zlib
from collections import Counter
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TypeVar

from tfloc.errors import TflocError

T = TypeVar("T")
_UTF16 = (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE, codecs.BOM_UTF32_LE, codecs.BOM_UTF32_BE)


def read_text(path: str | Path, error: type[TflocError], what: str, latin1: bool = False) -> str:
    """The text of ``path`` with LF line ends (a leading BOM dropped; ``.gz`` or gzip content
    decompressed). ``latin1``: bytes that are not UTF-8 are read as Latin-1 (old logs' host
    names) instead of being an error. Errors: ``error("<path>: …")``, naming ``what`` it should be."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise error(f"{path}: is a directory, not a {what}") from None
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    if data[:2] == b"\x1f\x8b":
        try:
            data = gzip.decompress(data)
        except (OSError, EOFError, zlib.error) as exc:
            raise error(f"{path}: damaged gzip data ({exc})") from None
    if data.startswith(_UTF16):
        raise error(f"{path}: UTF-16/32 text; save the {what} as UTF-8")
    nul = data.find(b"\x00")
    if nul >= 0:
        raise error(f"{path}: binary data (byte {nul} is NUL), not a {what}")
    if data.startswith(codecs.BOM_UTF8):
        data = data[len(codecs.BOM_UTF8):]
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        if not latin1:
            line = data[:exc.start].count(b"\n") + 1
            raise error(f"{path}:{line}: not UTF-8 text (byte {exc.start}); save the {what} as UTF-8") from None
        text = data.decode("latin-1")
    return text.replace("\r\n", "\n")


def parse_text(path: str | Path, error: type[TflocError], what: str, parse: Callable[[str], T],
               syntax: type[Exception] | tuple[type[Exception], ...], language: str) -> T:
    """``parse(read_text(path))``, a ``syntax`` error becoming ``error("<path>: not valid <language> (…)")``
    (so does a ValueError, e.g. an integer of more digits than Python converts)."""
    text = read_text(path, error, what)
    try:
        return parse(text)
    except (syntax, ValueError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise error(f"{path}: not valid {language} ({first})") from None
    except RecursionError:
        raise error(f"{path}: {language} nested too deeply") from None


def csv_rows(path: str | Path, error: type[TflocError], what: str,
             required: list[str] | tuple[str, ...]) -> tuple[list[str], Iterator[tuple[int, dict]]]:
    """The header of a CSV file and its rows as ``(line, row)`` (``line`` 1-based, as in an
    editor); a header lacking a ``required`` column is an error at line 1."""
    reader = csv.DictReader(io.StringIO(read_text(path, error, what), newline=""))
    try:
        header = list(reader.fieldnames or [])
    except csv.Error as exc:
        raise error(f"{path}:1: unreadable CSV header ({exc})") from None
    twice = sorted(c for c, n in Counter(header).items() if n > 1)
    if twice:
        raise error(f"{path}:1: header names column(s) {', '.join(map(repr, twice))} more than once")
    missing = [c for c in required if c not in header]
    if missing:
        raise error(f"{path}:1: header lacks column(s) {', '.join(missing)}")

    def rows() -> Iterator[tuple[int, dict]]:
        try:
            for row in reader:
                yield reader.line_num, row
        except csv.Error as exc:
            raise error(f"{path}:{reader.line_num}: unreadable CSV ({exc})") from None

    return header, rows()
