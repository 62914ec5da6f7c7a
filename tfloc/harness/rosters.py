"""Matcher rosters (``tfloc/rosters.toml``): named line-ups a study file or ``--matchers`` names
instead of typing the matchers out: ``matchers = "single-scan"`` is the roster, an entry
``"@trackers"`` in a list stands for its names in place (so a study extends a roster)."""

from __future__ import annotations

import tomllib
from functools import cache
from pathlib import Path

from tfloc.errors import ConfigError

ROSTERS_FILE = Path(__file__).resolve().parents[1] / "rosters.toml"
MARK = "@"


@cache
def rosters() -> dict[str, tuple[str, ...]]:
    """Every roster by name (read once)."""
    doc = tomllib.loads(ROSTERS_FILE.read_text(encoding="utf-8"))
    return {k: tuple(v) for k, v in doc.items()}


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
