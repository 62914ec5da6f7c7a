"""The README as a front page: its generated blocks (and the docs') are what the committed run
directories give (docs/matchers.md's table what the matchers' declarations give, checked without
the runs too), it stays short, and neither it nor docs/ carries dates, issue numbers or
session talk; every relative link of theirs goes somewhere."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from _paths import ROOT

from tfloc.core.registry import declarations
from tfloc.site.build import markdown_files, stale_markdown
from tfloc.site.collect import collect
from tfloc.site.markdown import REGISTRY_BLOCKS, block_names

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
FORBIDDEN = [r"20\d\d-\d\d-\d\d", r"\bissues?\s+#?\d+", r"\bthis\s+stop\b", r"\bstop\s+\d+"]
MAX_README_LINES = 250


@pytest.fixture(scope="module")
def committed():
    return collect(ROOT / "results")


def test_the_generated_blocks_are_what_the_committed_runs_give(committed) -> None:
    files = markdown_files(ROOT)
    assert ROOT / "README.md" in files
    names = block_names((ROOT / "README.md").read_text(encoding="utf-8"))
    assert {"advice", "single-scan-short", "tracking-short", "global-short", "kidnap-short",
            "robustness-short"} <= set(names)
    stale = [str(f.relative_to(ROOT)) for f in stale_markdown(files, committed)]
    assert not stale, f"generated blocks out of date (run 'tfloc site --readme'): {stale}"


def test_the_matchers_table_is_what_the_declarations_give() -> None:
    """docs/matchers.md's table lists every matcher the project's modules declare (no run read),
    and every declared docs page exists."""
    page = ROOT / "docs" / "matchers.md"
    assert set(REGISTRY_BLOCKS) <= set(block_names(page.read_text(encoding="utf-8")))
    stale = [str(f.relative_to(ROOT)) for f in stale_markdown(markdown_files(ROOT), None)]
    assert not stale, f"the matcher table is stale (run 'tfloc site --only-registry'): {stale}"
    text = page.read_text(encoding="utf-8")
    for d in declarations():
        assert f"| `{d.name}` |" in text
        assert (ROOT / "docs" / d.docs).is_file(), f"{d.path}: {d.name}'s page docs/{d.docs} is missing"


def test_the_readme_is_a_front_page() -> None:
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= MAX_README_LINES, f"README.md has {len(lines)} lines"


@pytest.mark.parametrize("path", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_dates_issue_numbers_or_session_talk(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    found = [m.group(0) for pat in FORBIDDEN for m in re.finditer(pat, text, flags=re.IGNORECASE)]
    assert not found, f"{path.name}: {found[:5]}"


@pytest.mark.parametrize("path", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    bad = [u for u in re.findall(r"\]\(([^)\s]+)\)", text)
           if not re.match(r"[a-z]+:", u) and not u.startswith("#") and not (path.parent / u.split("#")[0]).exists()]
    assert not bad, f"{path.name}: links to nothing: {bad}"
