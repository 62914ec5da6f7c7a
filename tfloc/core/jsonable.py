"""A value as ``run.json`` stores it and reads it back, without the text in between.

:func:`jsonable` is a JSON round trip (``json.dumps`` with ``default=str``, then ``json.loads``)
computed directly: a dataclass becomes its fields' dict (:func:`dataclasses.asdict`), a mapping a
dict with text keys, a tuple or list a list, a bool, int, float (NaN and ±inf kept), str or None
itself, anything else its ``str`` (a path, a NumPy integer). Fingerprints and recorded configurations compare equal to
what a later session reads from the file.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any


def _key(k: Any) -> str:
    if isinstance(k, bool):
        return "true" if k else "false"
    if k is None:
        return "null"
    if isinstance(k, float):
        if math.isnan(k):
            return "NaN"
        return ("Infinity" if k > 0 else "-Infinity") if math.isinf(k) else repr(float(k))
    return str(int(k)) if isinstance(k, int) else str.__str__(k)


def jsonable(value: Any) -> Any:
    """``value`` as JSON would give it back (module notes)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        value = dataclasses.asdict(value)
    if value is None:
        return None
    if isinstance(value, str):
        return str.__str__(value)
    if isinstance(value, bool):
        return bool(value)
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value)
    if isinstance(value, Mapping):
        return {_key(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    return str(value)
