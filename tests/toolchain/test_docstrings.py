"""Module docstrings say what, units and why in a few lines; the evidence lives in docs/."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest
from _paths import ROOT

SOURCES = sorted([*(ROOT / "tfloc").rglob("*.py"), *(ROOT / "baselines").rglob("*.py")])
MAX_LINES = 30


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_module_docstring_is_short_and_names_no_issue(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    doc = ast.get_docstring(ast.parse(text), clean=False) or ""
    assert len(doc.splitlines()) <= MAX_LINES, f"{path.name}: module docstring of {len(doc.splitlines())} lines"
    assert not re.search(r"\bissue \d+", text, flags=re.IGNORECASE), f"{path.name} names an issue number"
