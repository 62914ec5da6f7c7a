"""The site's HTML: the page shell (the one stylesheet and script inlined, no network), a
leaderboard as a sortable table whose rows carry their matcher's family (kind and origin, for
the filters) and whose cells link to their run's page, and the index: the statements, then one
section per page. Pure: strings in, strings out."""

from __future__ import annotations

import html
import math
from functools import cache
from pathlib import Path

from markdown_it import MarkdownIt

from tfloc.core.modes import SEQUENCE

from .advice import Statement
from .board import Board, Cell
from .collect import SiteData, run_note
from .cost import SLOPES_CSV
from .families import BASELINE, OWN, Family
from .pages import COST

STATIC = Path(__file__).with_name("static")
KINDS = ("single-scan", "tracker", "global", "?")
ORIGINS = ((OWN, "tfloc's own"), (BASELINE, "baselines and peers"))


@cache
def markdown() -> MarkdownIt:
    """CommonMark with tables; raw HTML in the source is shown as text."""
    return MarkdownIt("commonmark", {"html": False}).enable("table")


def inline(text: str) -> str:
    """Markdown inline (``code``, *emphasis*) as HTML."""
    return markdown().renderInline(text)


def shell(title: str, body: str, home: str = "", generator: str = "") -> str:
    """A complete page: ``body`` inside the shell; ``home``: the relative link to the index;
    ``generator``: the identity of the code that drew it (a ``<meta name="generator">``)."""
    css = (STATIC / "site.css").read_text(encoding="utf-8")
    js = (STATIC / "site.js").read_text(encoding="utf-8")
    back = f'<p><a href="{html.escape(home)}">← all leaderboards</a></p>' if home else ""
    return ("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            + (f"<meta name=\"generator\" content=\"tfloc site {html.escape(generator)}\">" if generator else "")
            + f"<link rel=\"icon\" href=\"data:,\"><title>{html.escape(title)}</title>"
            f"<style>\n{css}</style></head>\n<body>\n<header class=\"top\">{back}</header>\n"
            f"<main>\n{body}\n</main>\n<script>\n{js}</script>\n</body></html>\n")


def _num(v: float) -> str:
    return "" if math.isnan(v) else f"{v:.6g}"


def cell_html(c: Cell | None, col_key: str, runs_href: str) -> str:
    """One table cell: ``data-v`` is what the sorter compares (and the test reads)."""
    if c is None:
        return f'<td class="empty" data-col="{html.escape(col_key)}">—</td>'
    cls = ' class="best"' if c.best else ""
    sub = f'<span class="cpu">{html.escape(c.sub)}</span>' if c.sub else ""
    href = f"{runs_href}/{c.run}/index.html"
    return (f'<td{cls} data-v="{_num(c.value)}" data-col="{html.escape(col_key)}">'
            f'<a href="{html.escape(href)}" title="{html.escape(c.title)}">'
            f'<span class="fig">{html.escape(c.text)}</span>{sub}</a></td>')


def board_html(board: Board, families: dict[str, Family], labels: dict[str, str],
               runs_href: str = "runs") -> str:
    """A leaderboard as a sortable table (``labels``: run directory → its page label)."""
    first = "descending" if board.higher else "ascending"
    heads = ['<th data-first="ascending"><button type="button">matcher</button></th>',
             '<th data-first="ascending"><button type="button">family</button></th>']
    for c in board.columns:
        what = f"{labels.get(c.run, c.run)}: {c.measure}"
        heads.append(f'<th data-first="{first}" data-col="{html.escape(c.key)}" title="{html.escape(what)}">'
                     f'<button type="button">{html.escape(c.label)}</button>'
                     f'<span class="run">{html.escape(c.run)}</span></th>')
    body = []
    for m in board.matchers:
        f = families.get(m, Family("?", BASELINE))
        tds = "".join(cell_html(board.cell(m, c), c.key, runs_href) for c in board.columns)
        body.append(f'<tr data-kind="{f.kind}" data-origin="{f.origin}" data-matcher="{html.escape(m)}">'
                    f'<th scope="row"><code>{html.escape(m)}</code></th>'
                    f'<td class="family">{f.kind} · {"tfloc" if f.origin == OWN else "baseline"}</td>{tds}</tr>')
    return (f'<div class="scroll"><table class="board sortable" id="board-{board.key}" '
            f'data-unit="{html.escape(board.unit)}"><thead><tr>{"".join(heads)}</tr></thead>'
            f'<tbody>\n' + "\n".join(body) + "\n</tbody></table></div>")


def filters_html() -> str:
    """The family filters (every box ticked: every row shown)."""
    kinds = "".join(f'<label><input type="checkbox" value="{k}" checked> {k if k != "?" else "unknown"}</label>'
                    for k in KINDS)
    origins = "".join(f'<label><input type="checkbox" value="{v}" checked> {t}</label>' for v, t in ORIGINS)
    return (f'<fieldset class="filters"><legend>Show matchers</legend><div>{kinds}</div>'
            f'<div>{origins}</div></fieldset>')


def statements_html(items: list[Statement]) -> str:
    """The "which localizer for which robot" list."""
    lis = "".join(f"<li><strong>{html.escape(s.question)}.</strong> {inline(s.answer)}</li>" for s in items)
    return (f'<section id="which"><h2>Which localizer for which robot</h2><p class="note">Every '
            f"statement below is computed from the leaderboards' rows when the site is built.</p>"
            f'<ul class="advice">{lis}</ul></section>')


def _notes(data: SiteData, dirs: list[str], slopes: frozenset[str] = frozenset()) -> str:
    """The runs a section reads and their state; ``slopes``: those read for their ``slopes.csv``."""
    items = "".join(f"<li>{inline(run_note(data.runs.get(d), d, SLOPES_CSV if d in slopes else None))}"
                    + (f' — <a href="runs/{d}/index.html">report</a>'
                       if data.runs.get(d) and data.runs[d].exists else "") + "</li>" for d in dirs)
    return f'<ul class="note">{items}</ul>'


def index_html(data: SiteData, families: dict[str, Family], results_label: str, generator: str = "") -> str:
    """The index page."""
    labels = {r.dir: r.label for p in data.pages for r in p.runs}
    toc = "".join(f'<a href="#{p.key}">{html.escape(p.title)}</a>' for p in data.pages)
    parts = [f"<h1>tfloc leaderboards</h1><p>Every matcher of the 2D laser localization benchmark on "
             f"the committed runs, one leaderboard per question. A cell: the share solved with its 95 % "
             f"interval, and the median CPU per scan; ★ marks a column's best only where the paired test "
             f"(exact McNemar, Holm-adjusted) separates it from the next. Click a header to sort; a cell "
             f"opens its run's report.</p><nav class=\"toc\"><a href=\"#which\">Which localizer</a>{toc}</nav>",
             filters_html(), statements_html(data.statements)]
    for p in data.pages:
        sec = [f'<section id="{p.key}"><h2>{html.escape(p.title)}</h2><p>{inline(p.about)}'
               + (f' <span class="muted">({html.escape(p.doc)})</span>' if p.doc else "") + "</p>"]
        keys = [COST, f"{COST}-slopes"] if p.key == COST else [p.key]
        for k in keys:
            b = data.boards.get(k)
            if b is None:
                continue
            if p.key == COST:
                sec.append(f"<h3>{html.escape(b.title)}</h3>")
            sec.append(board_html(b, families, labels) if b.columns else
                       '<p class="note">Not yet: no run of this page has figures.</p>')
        if p.key == SEQUENCE.page and data.targets:
            sec.append(f'<div class="targets"><h3>The tracking targets</h3>{markdown().render(data.targets)}</div>')
        dirs = [r.dir for r in p.runs] if p.key != COST else list(dict.fromkeys(
            c.run for k in (COST, f"{COST}-slopes") for c in data.boards[k].columns))
        slopes = frozenset(c.run for c in data.boards[f"{COST}-slopes"].columns) if p.key == COST else frozenset()
        sec.append(_notes(data, dirs, slopes) + "</section>")
        parts.append("".join(sec))
    parts.append(f'<footer class="muted">Written by <code>tfloc site</code> from {html.escape(results_label)}; '
                 f"the page → run mapping is <code>tfloc/site/pages.toml</code>.</footer>")
    return shell("tfloc leaderboards", "\n".join(parts), generator=generator)
