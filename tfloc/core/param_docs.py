"""What a matcher's parameters are: name, default and the one-line doc with its unit, read from
its configuration dataclass (``tfloc matchers``).

A field documents itself on its own line (``sigma: float = 0.05  #: … (metres)``, Sphinx's
same-line attribute doc) or in the class docstring's ``Attributes:`` section (``name: doc``,
several names before one colon share it; indented lines continue it). Nested configurations
(a field whose default is a dataclass) are listed field by field as ``outer.inner``.
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from dataclasses import dataclass
from typing import Any

_SAME_LINE = re.compile(r"^\s+(\w+)\s*:[^=#]*=.*?#:\s*(.+?)\s*$")
_ATTR = re.compile(r"^(\s*)([\w, ]+):\s*(.*)$")


@dataclass(frozen=True)
class ParamDoc:
    """One parameter: dotted ``name``, its ``default`` and its one-line ``doc`` (with unit)."""

    name: str
    default: Any
    doc: str


def _attributes(doc: str) -> dict[str, str]:
    """``name → doc`` of a docstring's ``Attributes:`` section."""
    out: dict[str, str] = {}
    lines = doc.splitlines()
    try:
        start = next(i for i, ln in enumerate(lines) if ln.strip() == "Attributes:")
    except StopIteration:
        return out
    indent, names = None, []
    for ln in lines[start + 1:]:
        if not ln.strip():
            continue
        m = _ATTR.match(ln)
        depth = len(ln) - len(ln.lstrip())
        if indent is None:
            indent = depth
        if depth < indent:
            break
        if depth == indent and m:
            names = [n.strip() for n in m.group(2).split(",") if n.strip()]
            for n in names:
                out[n] = m.group(3).strip()
        elif names:
            for n in names:
                out[n] = f"{out[n]} {ln.strip()}".strip()
    return out


def field_docs(cls: type) -> dict[str, str]:
    """``field → doc`` of a configuration dataclass (same-line ``#:`` docs win)."""
    out = _attributes(inspect.getdoc(cls) or "")
    try:
        source = inspect.getsource(cls)
    except (OSError, TypeError):
        return out
    for line in source.splitlines():
        m = _SAME_LINE.match(line)
        if m:
            out[m.group(1)] = m.group(2)
    return out


def describe(config: Any, prefix: str = "") -> list[ParamDoc]:
    """Every parameter of a configuration dataclass instance, nested ones as ``outer.inner``."""
    docs = field_docs(type(config))
    out = []
    for f in dataclasses.fields(config):
        value = getattr(config, f.name)
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            out += describe(value, f"{prefix}{f.name}.")
        else:
            out.append(ParamDoc(prefix + f.name, value, " ".join(docs.get(f.name, "").split())))
    return out
