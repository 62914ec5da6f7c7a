"""Matcher rosters (``tfloc/rosters.toml``): named line-ups a study file or ``--matchers`` names
instead of typing the matchers out: ``matchers = "single-scan"`` is the roster, an entry
``"@trackers"`` in a list stands for its names in place (so a study extends a roster).

A roster is the names the file lists, plus the registered matchers whose module declares that
they join it (``"rosters": ["trackers"]`` in its ``REGISTRY``, :mod:`tfloc.core.registry`) and
are not listed, in name order: in place of the entry :data:`JOINERS` (``"..."``) where the roster
has one (``trackers``: before dead reckoning, the floor), else after the listed names."""

from __future__ import annotations

import tomllib
from functools import cache
from pathlib import Path

from tfloc.core.registry import declarations
from tfloc.errors import ConfigError

ROSTERS_FILE = Path(__file__).resolve().parents[1] / "rosters.toml"
MARK = "@"
#: the entry of a roster's list that the matchers joining it by declaration take the place of
JOINERS = "..."


@cache
def listed() -> dict[str, tuple[str, ...]]:
    """Every roster by name as the file lists it (with its :data:`JOINERS` entry, if any)."""
    doc = tomllib.loads(ROSTERS_FILE.read_text(encoding="utf-8"))
    return {k: tuple(v) for k, v in doc.items()}


def joiners(roster: str) -> list[str]:
    """The registered matchers that join ``roster`` by declaration and are not listed in it, in
    name order."""
    names = set(listed().get(roster, ()))
    return sorted(d.name for d in declarations() if roster in d.rosters and d.name not in names)


@cache
def rosters() -> dict[str, tuple[str, ...]]:
    """Every roster by name: its listed names with its joiners in place (read once). A module
    that declares a roster the file does not name is one line naming both."""
    table = listed()
    for d in declarations():
        for r in d.rosters:
            if r not in table:
                raise ConfigError(f"{d.path}: matcher {d.name!r} joins roster {r!r}, which "
                                  f"{ROSTERS_FILE.name} does not name (known: {', '.join(table)})")
    out = {}
    for name, names in table.items():
        where = names.index(JOINERS) if JOINERS in names else len(names)
        out[name] = (*names[:where], *joiners(name), *names[where + 1:])
    return out


def expand(entries: str | list, where: str) -> list:
    """A study's ``matchers`` value with its rosters replaced by their names (order kept; a roster's
    name already listed is not added again). ``where`` names the key in errors."""
    items = [MARK + entries] if isinstance(entries, str) else entries
    if not isinstance(items, list):
        raise ConfigError(f"{where}: 'matchers' must be a list or a roster's name")
    out: list = []
    for e in items:
        if isinstance(e, str) and e.startswith(MARK):
            name = e[len(MARK):]
            if name not in rosters():
                raise ConfigError(f"{where}: no roster {name!r}; known: {', '.join(rosters())} "
                                  f"({ROSTERS_FILE.name})")
            out += [m for m in rosters()[name] if m not in out]
        else:
            out.append(e)
    return out
