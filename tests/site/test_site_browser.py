"""The site in a real browser: ``tfloc site`` on a small results root (two reported runs, a run
with only ``tracking.csv``, a scaling study), the index opened from disk in headless Chromium
(Debian's package, ``make browser``) through chromedriver: every leaderboard cell equals its
run's headline figure, a header click sorts its table, the family filter hides rows, every link
and image of every page resolves, no console error, no page wider than a phone's screen, and
screenshots at 1280 and 390 px wide."""

from __future__ import annotations

import math
import os
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest
from _site_results import results_root
from _webdriver import Browser, available

from tfloc.cli import main
from tfloc.report.headline import interval
from tfloc.site.pages import load_pages
from tfloc.site.rows import run_rows

CELLS = """return Array.from(document.querySelectorAll('table.board')).map(t => ({id: t.id,
  cells: Array.from(t.querySelectorAll('tbody tr')).flatMap(tr => Array.from(tr.querySelectorAll('td[data-col]'))
    .map(td => ({matcher: tr.dataset.matcher, col: td.dataset.col, v: td.dataset.v === undefined ? null : td.dataset.v,
                 fig: (td.querySelector('.fig') || td).textContent, best: td.classList.contains('best')})))}));"""
COLUMN = """const t = document.getElementById(arguments[0]);
return Array.from(t.tBodies[0].rows).map(r => r.cells[arguments[1]].dataset.v || r.cells[arguments[1]].textContent);"""
REFS = """return {links: Array.from(document.querySelectorAll('a[href]')).map(a => a.getAttribute('href')),
  images: Array.from(document.querySelectorAll('img')).map(i => [i.getAttribute('src'), i.complete, i.naturalWidth])};"""


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> tuple[Path, Path]:
    if not available():
        if os.environ.get("CI"):
            pytest.fail("Chromium and chromedriver are missing: .ci/run runs 'make browser' first")
        pytest.skip("no chromium/chromedriver here (make browser installs Debian's)")
    base = tmp_path_factory.mktemp("site")
    root = results_root(base / "results")
    out = base / "site"
    assert main(["site", "--results", str(root), "--out", str(out)]) == 0
    return root, out


def _expected(root: Path) -> dict[tuple[str, str], object]:
    """(board id, column key, matcher) → headline row, for every headline page's run."""
    out = {}
    for page in load_pages():
        for ref in page.runs:
            for r in run_rows(root, ref.dir).rows:
                if r.mode in ref.modes:
                    out[(f"board-{page.key}", f"{ref.dir}/{r.mode}/{r.scope}", r.matcher)] = r
    return out


def _resolves(page: Path, href: str) -> bool:
    parts = urlsplit(href)
    if parts.scheme in ("http", "https", "mailto", "data"):
        return True
    return not parts.path or (page.parent / unquote(parts.path)).exists()


def _check_page(b: Browser, page: Path) -> None:
    b.get(page.as_uri())
    b.execute("return document.readyState")
    refs = b.execute(REFS)
    bad = [h for h in refs["links"] if not _resolves(page, h)]
    assert not bad, f"{page}: links that go nowhere: {bad[:5]}"
    broken = [s for s, done, w in refs["images"] if not (done and w > 0)]
    assert not broken, f"{page}: images that do not load: {broken[:5]}"
    errors = [e for e in b.log() if e.get("level") == "SEVERE"]
    assert not errors, f"{page}: console errors: {errors[:3]}"


def test_the_site_in_a_browser(site, tmp_path: Path) -> None:
    root, out = site
    index = out / "index.html"
    with Browser(1280, 900) as b:
        b.get(index.as_uri())
        # every cell is its run's headline figure, and every figure has its cell
        expected, seen = _expected(root), set()
        boards = {t["id"]: t["cells"] for t in b.execute(CELLS)}
        for bid in (f"board-{p.key}" for p in load_pages() if p.key != "cost"):
            for c in boards.get(bid, []):
                r = expected.get((bid, c["col"], c["matcher"]))
                if r is None:
                    assert c["v"] is None, (bid, c)
                    continue
                seen.add((bid, c["col"], c["matcher"]))
                assert math.isclose(float(c["v"]), r.value_pct, rel_tol=1e-5), (bid, c, r)
                assert c["fig"] == interval(r), (bid, c, r)
                assert c["best"] == (r.rank == 1 and r.verdict == "ahead"), (bid, c, r)
        assert seen == set(expected)
        assert any(c["best"] for c in boards["board-single-scan"]), "the fixture's best is marked"
        assert not any(c["best"] for c in boards["board-tracking"]), "rows without a paired test are never marked"
        # a click on a header sorts its table: best first, then the other way
        b.click(b.find("#board-single-scan thead th:nth-child(3) button"))
        col = [float(v) for v in b.execute(COLUMN, "board-single-scan", 2) if v not in ("", "—")]
        assert col == sorted(col, reverse=True) and len(col) >= 2
        b.click(b.find("#board-single-scan thead th:nth-child(3) button"))
        col = [float(v) for v in b.execute(COLUMN, "board-single-scan", 2) if v not in ("", "—")]
        assert col == sorted(col)
        b.click(b.find("#board-single-scan thead th:nth-child(1) button"))
        names = b.execute(COLUMN, "board-single-scan", 0)
        assert names == sorted(names)
        # the family filter hides the baselines' rows
        b.click(b.find("fieldset.filters input[value=baseline]"))
        shown = b.execute("return Array.from(document.querySelectorAll('tr[data-origin]'))"
                          ".filter(r => r.offsetParent !== null).map(r => r.dataset.origin)")
        assert shown and set(shown) == {"tfloc"}
        b.click(b.find("fieldset.filters input[value=baseline]"))
        b.screenshot(tmp_path / "index-1280.png")
        b.set_window(390, 844)
        wide = b.execute("return [document.documentElement.scrollWidth, window.innerWidth]")
        assert wide[0] <= wide[1] + 1, f"the index is wider than a phone: {wide}"
        b.screenshot(tmp_path / "index-390.png")
        b.set_window(1280, 900)
        # every page: links and images resolve, no console error
        for page in [index, *sorted((out / "runs").glob("*/index.html"))]:
            _check_page(b, page)
    assert (tmp_path / "index-1280.png").stat().st_size > 10_000
    assert (tmp_path / "index-390.png").stat().st_size > 10_000
