"""Matcher parameters: a configuration dataclass with keyword overrides (the one way to configure
every matcher, the paper's, tf-plus and the baselines alike)."""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

from tfloc.errors import ParameterError

C = TypeVar("C")


def resolve_params(default: type[C], config: C | None, overrides: dict[str, Any]) -> C:
    """``config`` (or ``default()``) with the fields in ``overrides`` replaced.

    An unknown key raises :class:`~tfloc.errors.ParameterError` listing the known ones. Lists
    (e.g. gate schedules from a TOML file or the command line) become tuples.
    """
    base = config if config is not None else default()
    names = {f.name for f in dataclasses.fields(base)}
    unknown = sorted(set(overrides) - names)
    if unknown:
        raise ParameterError(f"unknown parameter(s) {', '.join(unknown)}; known: {', '.join(sorted(names))}")
    fixed = {k: tuple(v) if isinstance(v, list) else v for k, v in overrides.items()}
    return dataclasses.replace(base, **fixed)
