"""Configuration plumbing shared by the baseline matchers."""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

C = TypeVar("C")


def resolve_config(default: type[C], config: C | None, overrides: dict[str, Any]) -> C:
    """``config`` (or ``default()``) with the fields in ``overrides`` replaced.

    An unknown key raises ``TypeError`` (which :func:`tfloc.get_matcher` reports as a bad parameter).
    Sequence values (e.g. gate schedules given as lists on the command line) become tuples.
    """
    base = config if config is not None else default()
    names = {f.name for f in dataclasses.fields(base)}
    unknown = sorted(set(overrides) - names)
    if unknown:
        raise TypeError(f"unknown parameter(s) {', '.join(unknown)}; known: {', '.join(sorted(names))}")
    fixed = {k: tuple(v) if isinstance(v, list) else v for k, v in overrides.items()}
    return dataclasses.replace(base, **fixed)
