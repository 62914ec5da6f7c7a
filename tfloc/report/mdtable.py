"""Markdown tables and number formatting for reports (no dependency on tabulate)."""

from __future__ import annotations

import math
from collections.abc import Sequence


def num(x: object, digits: int = 2) -> str:
    """A number with ``digits`` decimals; missing/NaN → ``—``; integers stay integers."""
    if x is None:
        return "—"
    if isinstance(x, str):
        return x or "—"
    try:
        v = float(x)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return str(x)
    if math.isnan(v):
        return "—"
    if math.isinf(v):
        return "∞" if v > 0 else "−∞"
    if isinstance(x, int) or (digits == 0):
        return f"{v:.0f}"
    return f"{v:.{digits}f}"


def pm(mean: object, std: object, digits: int = 3) -> str:
    """``mean ± std`` (std omitted when missing)."""
    s = num(std, digits)
    return num(mean, digits) if s == "—" else f"{num(mean, digits)} ± {s}"


def table(headers: Sequence[str], rows: Sequence[Sequence[object]], align: str | None = None) -> str:
    """A GitHub-flavoured markdown table; ``align`` is one of l/r/c per column (default: l then r)."""
    align = align or ("l" + "r" * (len(headers) - 1))
    rule = {"l": ":--", "r": "--:", "c": ":-:"}
    esc = [[str(c).replace("|", "\\|") for c in r] for r in rows]
    lines = ["| " + " | ".join(headers) + " |", "| " + " | ".join(rule[a] for a in align) + " |"]
    lines += ["| " + " | ".join(r) + " |" for r in esc]
    return "\n".join(lines) + "\n"
