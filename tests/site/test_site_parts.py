"""The site's pure parts on hand-made rows: the page → run mapping, a run's rows only from its
``headline.csv`` (a run with other tables alone has no headline yet), the best mark only where the paired test says *ahead*, statements that say "not
yet" when the data cannot answer, generated blocks replaced between their markers, and a run
page whose links go only where something is."""

from __future__ import annotations

from pathlib import Path

import pytest
from _site_results import TRACKING_CSV

from tfloc.core.modes import MODES, TRUTH_FREE
from tfloc.errors import ConfigError
from tfloc.evaluation.headline import HeadlineRow
from tfloc.site.advice import statements
from tfloc.site.board import headline_board
from tfloc.site.collect import SiteData, run_note
from tfloc.site.families import family
from tfloc.site.markdown import refresh
from tfloc.site.pages import Page, RunRef, load_pages
from tfloc.site.rows import RunRows, run_rows
from tfloc.site.runpage import write_run_page


def _row(matcher: str, rank: int, value: float, verdict: str, scope: str = "real-a") -> HeadlineRow:
    return HeadlineRow("single", scope, rank, matcher, "success", value, value - 1, value + 1, 100, 1.0,
                       "median error", 2.0 * rank, verdict, "x", 0.01 if verdict == "ahead" else 0.5)


def test_every_page_names_its_runs_once() -> None:
    pages = load_pages()
    keys = [p.key for p in pages]
    assert keys[:5] == ["single-scan", "tracking", "global", "kidnap", "robustness"] and "cost" in keys
    assert all(r.dir.endswith("-quick") for p in load_pages(quick=True) for r in p.runs)
    for p in load_pages(quick=True):  # a run already quick (make bench's scaling-quick) is not renamed
        dirs = [r.dir for r in p.runs]
        assert len(set(dirs)) == len(dirs) and not any(d.endswith("-quick-quick") for d in dirs), dirs


def test_every_mode_is_shown_on_a_page() -> None:
    """The site finds a mode's board by its Mode.page: each must be a key of pages.toml."""
    keys = {p.key for p in load_pages()}
    assert {m.page for m in (*MODES.values(), TRUTH_FREE)} <= keys


def test_a_bad_pages_file_is_one_line(tmp_path: Path) -> None:
    f = tmp_path / "pages.toml"
    f.write_text("[[page]]\ntitle = 'no key'\n")
    with pytest.raises(ConfigError, match="without key"):
        load_pages(f)


def test_a_run_without_a_headline_has_no_rows_yet(tmp_path: Path) -> None:
    """The headline is computed once (``tfloc report``): a run whose other tables are there but
    whose ``headline.csv`` is not shows none, never rows remade from those tables."""
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "tracking.csv").write_text(TRACKING_CSV)
    rr = run_rows(tmp_path, "run")
    assert rr.exists and not rr.reported and rr.rows == []
    assert run_note(rr, "run").startswith("`results/run/`: no headline yet")
    assert not run_rows(tmp_path, "missing").exists


def test_a_scaling_run_is_noted_by_the_file_its_board_reads(tmp_path: Path) -> None:
    (tmp_path / "scaling").mkdir()
    rr = run_rows(tmp_path, "scaling")
    assert run_note(rr, "scaling").startswith("`results/scaling/`: no headline yet")
    assert run_note(rr, "scaling", "slopes.csv") == "`results/scaling/`: `slopes.csv`"
    assert run_note(run_rows(tmp_path, "missing"), "missing", "slopes.csv").endswith("not yet run")


def test_the_best_is_marked_only_where_the_paired_test_separates_it() -> None:
    page = Page("p", "P", "", "", (RunRef("run", "run", ("single",)),))
    rows = [_row("a", 1, 99.0, "tied"), _row("b", 2, 98.0, "ahead"), _row("c", 3, 50.0, ""),
            _row("a", 1, 99.0, "ahead", "real-b"), _row("b", 2, 60.0, "", "real-b")]
    board = headline_board(page, {"run": RunRows("run", Path("run"), True, "headline.csv", rows)})
    assert [c.scope for c in board.columns] == ["real-a", "real-b"]
    assert board.matchers == ["a", "b", "c"]
    best = {(m, c.scope) for (m, _), cell in board.cells.items() for c in board.columns
            if cell.best and c.key == _}
    assert best == {("a", "real-b")}


def test_statements_say_not_yet_without_data() -> None:
    for s in statements({}):
        assert s.answer.startswith("Not yet"), s


def test_statements_name_the_leader_and_the_cheapest() -> None:
    page = Page("single-scan", "single", "", "", (RunRef("run", "run", ("single",)),))
    rows = [_row("a", 1, 99.0, "ahead"), _row("b", 2, 98.5, "")]
    board = headline_board(page, {"run": RunRows("run", Path("run"), True, "headline.csv", rows, {"real-a": "real"})})
    said = {s.question: s.answer for s in statements({"single-scan": board})}
    assert said["The most accurate single scan on real logs"].startswith("`a` ranks first")
    assert "ahead of the next on every one" in said["The most accurate single scan on real logs"]
    assert said["A single scan on a small CPU budget"].startswith("`a`: the cheapest")


def test_blocks_are_replaced_between_their_markers() -> None:
    data = SiteData(Path("."), [], {}, statements=statements({}))
    text = "intro\n<!-- tfloc:begin advice -->\nold\n<!-- tfloc:end advice -->\nend\n"
    new = refresh(text, data)
    assert new.startswith("intro\n<!-- tfloc:begin advice -->\n- **") and new.endswith("<!-- tfloc:end advice -->\nend\n")
    assert "old" not in new and refresh(new, data) == new
    with pytest.raises(ConfigError, match="unknown generated block"):
        refresh("<!-- tfloc:begin nope -->\n<!-- tfloc:end nope -->\n", data)


def test_families() -> None:
    assert family("tf-plus-changed").origin == "tfloc" and family("tf-plus-changed").kind == "single-scan"
    assert family("amcl-tuned").origin == "baseline" and family("amcl-tuned").kind == "tracker"
    assert family("tf-global").kind == "global" and family("no-such-matcher").kind == "?"


def test_a_run_page_links_only_where_something_is(tmp_path: Path) -> None:
    run = tmp_path / "results" / "r"
    (run / "figures").mkdir(parents=True)
    (run / "figures" / "a.png").write_bytes(b"\x89PNG")
    (run / "paired.csv").write_text("x\n")
    (run / "report.md").write_text("# r\n\n![a](figures/a.png) ![b](figures/b.png) [t](timing.md) "
                                   "[p](paired.csv) [gone](gone.csv) <script>x</script>\n")
    (run / "timing.md").write_text("# timing\n")
    page = write_run_page(run, tmp_path / "site" / "runs" / "r", "r", "../../index.html")
    html = page.read_text()
    assert 'src="../../../results/r/figures/a.png"' in html and "[b: not in the run]" in html
    assert 'href="#note-timing-md"' in html and 'href="../../../results/r/paired.csv"' in html
    assert "gone.csv" not in html and "<script>x</script>" not in html
