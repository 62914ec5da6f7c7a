"""A matcher's family on the site: its kind (single-scan, tracker or global, as ``tfloc
matchers`` says, a preset's being its matcher's) and its origin: tfloc's own (the paper's
method and the project's variants: ``tfloc.paper``, ``tfloc.tfplus``, ``tfloc.relocalize``) or
a baseline or peer (everything else, dead reckoning included)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from tfloc.core.matcher import factory_of, kind_of
from tfloc.core.presets import resolve
from tfloc.errors import TflocError

#: the packages that hold tfloc's own methods
OWN_PACKAGES = ("tfloc.paper", "tfloc.tfplus", "tfloc.relocalize")
OWN, BASELINE = "tfloc", "baseline"
UNKNOWN = "?"


@dataclass(frozen=True)
class Family:
    """``kind``: single-scan, tracker, global or ? (not importable here); ``origin``: tfloc or baseline."""

    kind: str
    origin: str


@cache
def family(label: str) -> Family:
    """The family of a matcher label (a registered name, a preset or ``base[key=value]``)."""
    try:
        base, _ = resolve(label, {})
        f = factory_of(label)
    except (TflocError, ImportError, OSError):
        return Family(UNKNOWN, BASELINE)
    module = getattr(f, "__module__", "") or ""
    own = any(module == p or module.startswith(p + ".") for p in OWN_PACKAGES) and ":" not in base
    return Family(kind_of(f), OWN if own else BASELINE)
