"""The table of the project's matchers in docs/matchers.md (generated block ``matchers``): one row
per matcher its modules declare (:mod:`tfloc.core.registry`), in the registry's order, with what
it is (the declaration's summary), the files it lives in (repository paths) and its docs page.
It reads no run directory, and no module of a matcher is imported. Links are relative to docs/."""

from __future__ import annotations

from tfloc.core.registry import Declaration, declarations
from tfloc.report.mdtable import table

HEADERS = ("name", "what", "module", "docs")


def _row(d: Declaration) -> list[str]:
    files = ", ".join(f"`{f}`" for f in (d.path, *d.files))
    return [f"`{d.name}`", d.summary, files, f"[{d.docs}]({d.docs})"]


def matchers_markdown() -> str:
    """The Markdown table of every declared matcher."""
    return table(list(HEADERS), [_row(d) for d in declarations()], "llll")
