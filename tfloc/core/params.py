"""Matcher parameters: a configuration dataclass with keyword overrides (the one way to configure
every matcher, the paper's, tf-plus and the baselines alike).

A configuration dataclass may declare the values its parameters may take in a class variable
``RULES`` (rule → the names of the parameters it applies to): ``"> 0"``, ``">= 0"``, ``">= 1"``,
``"(0, 1]"``, ``"[0, 1]"``, ``"(0, 1)"``, ``"finite"``, or a tuple of allowed strings. A rule on a
tuple parameter applies to each element (and the tuple must not be empty); ``None`` (for an
optional parameter) passes. Every value is also checked against the type of its default:
a bool for a bool, an integer for an int, a finite number for a float, a string for a string, a
list of such for a tuple, a table (dict) of overrides for a nested configuration. So a matcher
built from a run configuration either works or raises :class:`~tfloc.errors.ParameterError`
naming the parameter — at construction, before any scan is touched.
"""

from __future__ import annotations

import dataclasses
import math
import typing
from collections.abc import Callable
from typing import Any, ClassVar, TypeVar

from tfloc.errors import ParameterError

C = TypeVar("C")

_RULES: dict[str, Callable[[float], bool]] = {
    "> 0": lambda v: v > 0,
    ">= 0": lambda v: v >= 0,
    ">= 1": lambda v: v >= 1,
    "(0, 1]": lambda v: 0 < v <= 1,
    "[0, 1]": lambda v: 0 <= v <= 1,
    "(0, 1)": lambda v: 0 < v < 1,
    "finite": lambda v: True,  # (every number is checked to be finite)
}


class Configured:
    """Base of a matcher configured by one dataclass, ``CONFIG``: ``Matcher(config=None,
    **overrides)`` sets ``self.config`` through :func:`resolve_params` (a matcher that builds
    more at construction writes its own ``__init__`` calling it)."""

    CONFIG: ClassVar[type]

    def __init__(self, config: Any = None, **overrides: Any) -> None:
        self.config = resolve_params(self.CONFIG, config, overrides)


def resolve_params(default: type[C], config: C | None, overrides: dict[str, Any]) -> C:
    """``config`` (or ``default()``) with the fields in ``overrides`` replaced, then checked.

    An unknown key raises :class:`~tfloc.errors.ParameterError` listing the known ones; a value of
    the wrong type or outside its rule (see the module notes) raises it naming the parameter.
    Lists (e.g. gate schedules from a TOML file or the command line) become tuples; a table for a
    nested configuration overrides its fields.
    """
    base = config if config is not None else default()
    out = _replace(base, overrides, "")
    check_params(out)
    return out


def _replace(base: Any, overrides: dict[str, Any], prefix: str) -> Any:
    names = {f.name for f in dataclasses.fields(base)}
    unknown = sorted(set(overrides) - names)
    if unknown:
        raise ParameterError(f"unknown parameter(s) {', '.join(prefix + u for u in unknown)}; known: "
                             f"{', '.join(sorted(names))}", tuple(prefix + u for u in unknown))
    fixed = {k: _typed(prefix + k, v, *_like(type(base), k, getattr(base, k))) for k, v in overrides.items()}
    return dataclasses.replace(base, **fixed)


_SAMPLES = {float: 0.0, int: 0, str: "", bool: False}


def _like(cls: type, name: str, current: Any) -> tuple[Any, bool]:
    """A value of the parameter's type, and whether it may be ``None`` (``float | None = None``:
    the type comes from the annotation)."""
    if current is not None:
        return current, False
    try:
        hint = typing.get_type_hints(cls).get(name)
    except (NameError, TypeError):
        return None, True
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    return (_SAMPLES.get(args[0]) if len(args) == 1 else None), True


def _bad(name: str, want: str, value: Any) -> ParameterError:
    return ParameterError(f"{name} must be {want}, got {value!r}", (name,))


def _typed(name: str, value: Any, current: Any, optional: bool = False) -> Any:
    """``value`` as the type of the parameter's current value ``current`` (or a ParameterError)."""
    if current is None or (value is None and optional):
        return value
    if dataclasses.is_dataclass(current):
        if isinstance(value, type(current)):
            return value
        if not isinstance(value, dict):
            raise _bad(name, f"a table of {type(current).__name__} parameters", value)
        return _replace(current, value, f"{name}.")
    if isinstance(current, bool):
        if not isinstance(value, bool):
            raise _bad(name, "true or false", value)
        return value
    if isinstance(current, int):
        if isinstance(value, bool) or not isinstance(value, int):
            raise _bad(name, "an integer", value)
        return value
    if isinstance(current, float):
        if isinstance(value, bool) or not isinstance(value, int | float) or math.isnan(value) or (
                math.isinf(value) and not math.isinf(current)):  # inf only where the default is
            raise _bad(name, "a finite number", value)
        return float(value)
    if isinstance(current, str):
        if not isinstance(value, str):
            raise _bad(name, "a string", value)
        return value
    if isinstance(current, tuple):
        if not isinstance(value, list | tuple):
            raise _bad(name, "a list", value)
        like = current[0] if current else None
        return tuple(_typed(f"{name}[{i}]", v, like) for i, v in enumerate(value))
    if not isinstance(value, type(current)):
        raise _bad(name, f"of type {type(current).__name__}", value)
    return value


def check_params(config: Any, prefix: str = "") -> None:
    """Check ``config`` (and its nested configurations) against its ``RULES``."""
    rules = {name: rule for rule, names in getattr(type(config), "RULES", {}).items() for name in names}
    for f in dataclasses.fields(config):
        name, value = prefix + f.name, getattr(config, f.name)
        if dataclasses.is_dataclass(value):
            check_params(value, f"{name}.")
        rule = rules.get(f.name)
        if rule is None:
            continue
        if isinstance(rule, tuple):
            if value not in rule:
                raise _bad(name, f"one of {', '.join(map(repr, rule))}", value)
            continue
        values = value if isinstance(value, tuple) else (value,)
        if value is None:
            continue
        if isinstance(value, tuple) and not value:
            raise _bad(name, "a non-empty list", value)
        if not all(_RULES[rule](v) for v in values):
            raise _bad(name, f"{'all ' if isinstance(value, tuple) else ''}{rule}", value)
