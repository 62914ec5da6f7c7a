"""Mutation fuzzing of the readers (tests/io/test_fuzz_readers.py): hypothesis strategies that turn a
valid file into a damaged one, and the oracle every damaged input must satisfy.

The oracle: reading ends in a valid result or in a :class:`~tfloc.errors.TflocError` whose one-line
message names the file (and its line, where the format has lines); never another exception type
and never a hang (each input runs under a time limit). ``TFLOC_FUZZ_EXAMPLES`` sets the inputs per
reader (``make test``: a few hundred, ``make fuzz``: thousands); every test prints how many it tried.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import resource
import signal
import traceback
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import yaml
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

from tfloc.errors import TflocError

EXAMPLES = int(os.environ.get("TFLOC_FUZZ_EXAMPLES", "200"))
TIME_LIMIT_S = float(os.environ.get("TFLOC_FUZZ_TIME_LIMIT_S", "20"))
MEMORY_LIMIT = 6 << 30  # bytes of address space while a case runs: a reader must not try to eat the machine

#: hypothesis settings of every reader's test: deterministic in ``make test`` (no flakes),
#: random in ``make fuzz`` (``TFLOC_FUZZ_RANDOM=1``).
SETTINGS = settings(max_examples=EXAMPLES, deadline=None, database=None,
                    derandomize=not os.environ.get("TFLOC_FUZZ_RANDOM"),
                    suppress_health_check=list(HealthCheck), print_blob=True)

#: for a reader reached through a whole command that is costly per input (``tfloc report``): an
#: eighth of the inputs in ``make test``, all of them in ``make fuzz``
REPORT_SETTINGS = settings(SETTINGS, max_examples=max(1, EXAMPLES // (1 if os.environ.get("TFLOC_FUZZ_RANDOM") else 8)))

#: what a damaged number may become
NUMBERS = ["nan", "NaN", "inf", "-inf", "Infinity", "1e308", "-1e308", "1e309", "-1", "-0.0", "0",
           "1e-320", "", "x", "0x1p3", "1_000", "9" * 400, "-7.5", "3e5"]
_NUMBER = re.compile(rb"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


class Hang(Exception):
    """A case ran past its time limit."""


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`Hang` in the running code after ``seconds`` of the process's CPU time
    (SIGPROF; main thread only): on a shared machine wall time is inflated, CPU time is not."""
    def alarm(signum, frame):  # noqa: ARG001
        raise Hang(f"no result after {seconds:g} s of CPU")

    old = signal.signal(signal.SIGPROF, alarm)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, old)


@contextlib.contextmanager
def memory_limit(limit: int = MEMORY_LIMIT) -> Iterator[None]:
    """Limit the address space while a case runs (a MemoryError is then a defect, not a swap storm)."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    used = _address_space()
    new = used + limit if hard == resource.RLIM_INFINITY else min(hard, used + limit)
    resource.setrlimit(resource.RLIMIT_AS, (new, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def _address_space() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * resource.getpagesize()


# ---------------------------------------------------------------------------------------------
# Mutations of bytes and lines


def _lines(data: bytes) -> list[bytes]:
    return data.split(b"\n")


def _fields(line: bytes, sep: bytes | None) -> list[bytes]:
    return line.split(sep) if sep is not None else line.split()


def _join(fields: list[bytes], sep: bytes | None) -> bytes:
    return (sep if sep is not None else b" ").join(fields)


@st.composite
def byte_mutation(draw, data: bytes, sep: bytes | None) -> tuple[str, bytes]:
    """One mutation of ``data`` (``sep``: the field separator of a line; ``None`` = whitespace)."""
    ops = ["truncate", "flip", "insert", "number", "number", "number", "swap-columns",
           "swap-fields", "duplicate-column", "duplicate-line", "delete-line", "empty-line",
           "huge-line", "huge-field", "crlf-bom"]
    op = draw(st.sampled_from(ops))
    n = len(data)
    lines = _lines(data)
    if op == "truncate":
        k = draw(st.integers(0, max(0, n - 1)))
        return f"truncate@{k}", data[:k]
    if op == "flip":
        k, bit = draw(st.integers(0, max(0, n - 1))), draw(st.integers(0, 7))
        b = bytearray(data)
        if b:
            b[k] ^= 1 << bit
        return f"flip@{k}.{bit}", bytes(b)
    if op == "insert":
        k = draw(st.integers(0, n))
        ins = draw(st.one_of(st.binary(min_size=1, max_size=8),
                             st.sampled_from([b",", b"\n", b"\r", b'"', b"\x00", b"\xff", b" ", b"\t",
                                              b"{", b"]", b"#", b"\xef\xbb\xbf", b"-"])))
        return f"insert@{k}:{ins!r}", data[:k] + ins + data[k:]
    if op == "number":
        found = list(_NUMBER.finditer(data))
        if not found:
            return "number:none", data
        m = found[draw(st.integers(0, len(found) - 1))]
        new = draw(st.sampled_from(NUMBERS)).encode()
        return f"number@{m.start()}:{m.group()!r}->{new[:12]!r}", data[:m.start()] + new + data[m.end():]
    if op == "crlf-bom":
        return "crlf-bom", b"\xef\xbb\xbf" + data.replace(b"\n", b"\r\n")
    i = draw(st.integers(0, max(0, len(lines) - 1)))
    if op == "duplicate-line":
        return f"duplicate-line@{i}", b"\n".join(lines[:i + 1] + lines[i:])
    if op == "delete-line":
        return f"delete-line@{i}", b"\n".join(lines[:i] + lines[i + 1:])
    if op == "empty-line":
        blank = draw(st.sampled_from([b"", b" ", b"\t", b"\r"]))
        return f"empty-line@{i}", b"\n".join(lines[:i] + [blank] + lines[i:])
    if op == "huge-line":
        size = draw(st.sampled_from([10_000, 200_000, 2_000_000]))
        fill = draw(st.sampled_from([b"1 ", b"A", b"1,", b"9", b"-"]))
        return f"huge-line@{i}x{size}", b"\n".join(lines[:i] + [fill * (size // len(fill))] + lines[i:])
    fields = _fields(lines[i], sep)
    if len(fields) < 2:
        return f"{op}:short-line", data
    a, b = sorted(draw(st.lists(st.integers(0, len(fields) - 1), min_size=2, max_size=2, unique=True)))
    every = op in ("swap-columns", "duplicate-column")
    out = []
    for j, line in enumerate(lines):
        f = _fields(line, sep)
        if (every or j == i) and len(f) > b:
            if op in ("swap-columns", "swap-fields"):
                f[a], f[b] = f[b], f[a]
            elif op == "duplicate-column":
                f.insert(b, f[a])
            line = _join(f, sep)
        elif op == "huge-field" and j == i and len(f) > a:
            f[a] = f[a] * draw(st.sampled_from([1000, 20_000]))
            line = _join(f, sep)
        out.append(line)
    return f"{op}@{i}:{a},{b}", b"\n".join(out)


@st.composite
def mutated(draw, data: bytes, sep: bytes | None = None, max_ops: int = 3) -> tuple[list[str], bytes]:
    """``data`` after 1..``max_ops`` mutations; returns what was done and the result."""
    done = []
    for _ in range(draw(st.integers(1, max_ops))):
        what, data = draw(byte_mutation(data, sep))
        done.append(what)
    return done, data


# ---------------------------------------------------------------------------------------------
# Mutations of JSON / YAML documents (the structure, not only the bytes)

_SCALARS = st.one_of(st.none(), st.booleans(), st.integers(-10**30, 10**30),
                     st.floats(allow_nan=True, allow_infinity=True),
                     st.sampled_from([1e308, -1e308, 0.0, -0.0, -1.0, 1e-320]),
                     st.text(max_size=12), st.sampled_from(["", "../x", "/", "nan", "1.0"]))
_VALUES = st.recursive(_SCALARS, lambda kids: st.one_of(st.lists(kids, max_size=4),
                                                        st.dictionaries(st.text(max_size=6), kids, max_size=3)),
                       max_leaves=8)


def _paths(doc, prefix=()) -> list[tuple]:
    out = [prefix]
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += _paths(v, (*prefix, i))
    return out


def _set(doc, path: tuple, value, delete: bool):
    if not path:
        return value
    parent = doc
    for k in path[:-1]:
        parent = parent[k]
    if delete:
        del parent[path[-1]]
    else:
        parent[path[-1]] = value
    return doc


@st.composite
def doc_mutation(draw, doc) -> tuple[list[str], object]:
    """The document with 1–3 values replaced by arbitrary JSON values, or deleted."""
    doc = json.loads(json.dumps(doc))
    done = []
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        path = paths[draw(st.integers(0, len(paths) - 1))]
        delete = bool(path) and draw(st.booleans())
        value = None if delete else draw(_VALUES)
        doc = _set(doc, path, value, delete)
        done.append(f"{'del' if delete else 'set'} {'/'.join(map(str, path))}" + ("" if delete else f"={value!r:.40}"))
    return done, doc


def dump_json(doc) -> bytes:
    return json.dumps(doc, indent=1).encode()


def dump_yaml(doc) -> bytes:
    return yaml.safe_dump(doc, sort_keys=False).encode()


_DUMP = {".json": (json.loads, dump_json), ".geojson": (json.loads, dump_json), ".yaml": (yaml.safe_load, dump_yaml)}
_SEP = {".csv": b",", ".pgm": b" "}


@st.composite
def damaged(draw, files: dict[str, bytes], weights: dict[str, int] | None = None) -> tuple[list[str], dict[str, bytes]]:
    """``files`` (name → bytes) with one of them damaged: its bytes (fields split at the format's
    separator), or for JSON/YAML also its document. Returns what was done and the files."""
    names = [n for n in sorted(files) for _ in range((weights or {}).get(n, 1))]
    name = draw(st.sampled_from(names))
    suffix = os.path.splitext(name)[1]
    byte_damage = mutated(files[name], _SEP.get(suffix))
    if suffix in _DUMP:
        load, dump = _DUMP[suffix]
        what, blob = draw(st.one_of(byte_damage, doc_mutation(load(files[name]))))
        blob = blob if isinstance(blob, bytes) else dump(blob)
    else:
        what, blob = draw(byte_damage)
    return [name, *what], {**files, name: blob}


def write_files(root, files: dict[str, bytes]) -> None:
    for name, blob in files.items():
        (root / name).write_bytes(blob)


# ---------------------------------------------------------------------------------------------
# The oracle


@dataclass
class Tally:
    """What one reader's fuzz test saw: inputs tried, valid results, TflocErrors, defects."""

    reader: str
    tried: int = 0
    valid: int = 0
    errors: int = 0
    defects: list[str] = field(default_factory=list)
    kinds: Counter = field(default_factory=Counter)

    def line(self) -> str:
        kinds = ", ".join(f"{k} ×{n}" for k, n in self.kinds.most_common(8))
        return (f"fuzz {self.reader}: {self.tried} inputs tried, {self.valid} valid, {self.errors} TflocError, "
                f"{len(self.defects)} defect(s)" + (f" [{kinds}]" if kinds else ""))


def judge(tally: Tally, what: list[str], read: Callable[[], object], names: list[str],
          line_re: str | None = None) -> None:
    """Run ``read`` on one damaged input and check the oracle; a defect is recorded in ``tally``.

    ``names``: strings one of which a TflocError's message must contain (the file or directory);
    ``line_re``: if given, a regex the message must match (e.g. ``path(:\\d+)?: ``).
    """
    tally.tried += 1
    try:
        with memory_limit(), time_limit(TIME_LIMIT_S):
            read()
    except TflocError as exc:
        msg = str(exc)
        problems = []
        if "\n" in msg:
            problems.append("message spans lines")
        if not any(n in msg for n in names):
            problems.append(f"message names none of {names}")
        if line_re is not None and not re.search(line_re, msg):
            problems.append(f"message does not match {line_re!r}")
        if problems:
            _defect(tally, what, f"{type(exc).__name__}: {'; '.join(problems)}: {msg[:300]!r}",
                    f"{type(exc).__name__} message")
        else:
            tally.errors += 1
    except Exception as exc:  # noqa: BLE001 - exactly what the oracle forbids
        frame = traceback.extract_tb(exc.__traceback__)[-1]
        where = f"{os.path.basename(frame.filename)}:{frame.lineno}"
        _defect(tally, what, f"{type(exc).__name__} at {where}: {str(exc)[:300]}", f"{type(exc).__name__} {where}")
    else:
        tally.valid += 1


def _defect(tally: Tally, what: list[str], text: str, kind: str) -> None:
    tally.kinds[kind] += 1
    tally.defects.append(f"{what}: {text}")


def finish(tally: Tally) -> None:
    """Print the tally (``make fuzz`` shows it) and fail if any input broke the oracle."""
    print(tally.line(), flush=True)
    assert not tally.defects, tally.line() + "\n" + "\n".join(tally.defects[:10])
