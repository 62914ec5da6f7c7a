"""The one comparison of a regenerated file with its committed copy.

Generators write numbers rounded to fixed decimals, so the same code on another CPU writes the
same bytes unless a value computed through numpy's SIMD transcendental ufuncs (``cos``, ``sin``,
``arctan2``, …) or LAPACK lands within one last-bit rounding of a written digit's boundary. A text
file therefore passes when it has the same bytes, or else the same lines with the same text
between its numbers and every decimal number within one unit of its last written digit (integers
exactly). Binary files (PGM maps) must have the same bytes. ``make test`` runs the tests that use
it again with AVX-512 and with AVX2 disabled (``make test-cpu``)."""

from __future__ import annotations

import re
from pathlib import Path

_NUMBER = re.compile(r"(-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)")


def _unit(token: str) -> float | None:
    """One unit of a number's last written digit; ``None`` for an integer (compared exactly)."""
    mant, _, exp = token.lower().partition("e")
    if "." not in mant and not exp:
        return None
    decimals = len(mant.partition(".")[2])
    return 10.0 ** (int(exp or 0) - decimals)


def _line_difference(a: str, b: str) -> str | None:
    """Why line ``a`` is not ``b`` within the last written digit, or ``None`` if it is."""
    pa, pb = _NUMBER.split(a), _NUMBER.split(b)
    if len(pa) != len(pb):
        return "a different number of fields"
    for k, (x, y) in enumerate(zip(pa, pb, strict=True)):
        if x == y:
            continue
        if k % 2 == 0:
            return f"text {x!r} != {y!r}"
        ux, uy = _unit(x), _unit(y)
        if ux is None or uy is None:
            return f"number {x} != {y}"
        if abs(float(x) - float(y)) > min(ux, uy) * (1 + 1e-9):
            return f"number {x} != {y} (more than one unit of the last written digit)"
    return None


def assert_same_file(made: Path, committed: Path) -> None:
    """``made`` equals ``committed``: byte for byte, or for text, within the last written digit."""
    a, b = Path(made).read_bytes(), Path(committed).read_bytes()
    if a == b:
        return
    try:
        la, lb = a.decode("utf-8").splitlines(), b.decode("utf-8").splitlines()
    except UnicodeDecodeError:
        raise AssertionError(f"{committed}: the regenerated binary file differs") from None
    assert len(la) == len(lb), f"{committed}: {len(la)} lines regenerated, {len(lb)} committed"
    for i, (x, y) in enumerate(zip(la, lb, strict=True), start=1):
        why = _line_difference(x, y)
        assert why is None, f"{committed}:{i}: {why}"
