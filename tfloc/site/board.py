"""A leaderboard: rows = matchers, columns = a page's datasets run by run (each run's pooled
``all`` first, where it has one), cells = the mode's headline figure with its 95 % interval and
CPU per scan (ms). A cell is marked best only where its matcher ranks first in that column and
the paired test separates it from the next (verdict ``ahead``). Pure: reads no file."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from tfloc.core.rows.headline import POOLED, HeadlineRow
from tfloc.evaluation.headline import TRUTH_FREE
from tfloc.report.headline import interval

from .pages import Page
from .rows import RunRows


@dataclass(frozen=True)
class Column:
    """One column: ``scope`` (a dataset or ``all``) of run ``run`` in headline mode ``mode``;
    ``kind``: the dataset's (:mod:`tfloc.site.kinds`; empty for ``all`` or where unknown)."""

    run: str
    mode: str
    scope: str
    measure: str
    figure: str = ""  # a headline row's extra figure shown instead of its measure (:data:`EXTRAS`)
    note: str = ""  #: shown after the label, e.g. a re-timing's ``contended (×1.42 inflated)``
    kind: str = ""

    @property
    def key(self) -> str:
        return f"{self.run}/{self.mode}/{self.scope}" + (f"/{self.figure}" if self.figure else "")

    @property
    def label(self) -> str:
        if self.mode == "re-timing":
            return "re-timing" + (f", {self.note}" if self.note else "")
        where = "pooled" if self.scope == POOLED else self.scope
        if self.figure:
            return f"{EXTRAS[self.figure][0]} ({where})"
        return f"{where} (no truth)" if self.measure == TRUTH_FREE else where


#: a tracking row's extra figures, each its own column: field → (label, what it is, format)
EXTRAS = {"truth_free_score": ("truth-free", "the truth-free verdict made with the truth hidden "
                               "(believed tracked %, docs/truth-free.md)", "{:.1f}"),
          "self_auc": ("self-AUC", "the tracker's own confidence as a lost-detector (ROC AUC against "
                       "not tracked; 0.5 = chance)", "{:.2f}")}


@dataclass(frozen=True)
class Cell:
    """What a column sorts by (``value``), what it shows (``text``, ``sub``), its tooltip, the
    best mark, the run it links to and the headline row it came from (if any)."""

    value: float
    text: str
    sub: str
    title: str
    best: bool
    run: str
    row: HeadlineRow | None = None


@dataclass
class Board:
    """A leaderboard; ``higher``: whether a larger value is better (the sorter's first order)."""

    key: str
    title: str
    columns: list[Column]
    matchers: list[str]
    cells: dict[tuple[str, str], Cell] = field(default_factory=dict)
    higher: bool = True
    unit: str = "%"

    def cell(self, matcher: str, column: Column) -> Cell | None:
        return self.cells.get((matcher, column.key))


def is_best(r: HeadlineRow) -> bool:
    """Rank 1 and separated from the next by the paired test."""
    return r.rank == 1 and r.verdict == "ahead"


def cpu_text(ms: float) -> str:
    """CPU per scan in ms, with the digits that matter."""
    if math.isnan(ms):
        return ""
    return f"{ms:.3g} ms" if ms < 10 else f"{ms:.0f} ms"


def tooltip(r: HeadlineRow) -> str:
    """n, error and the paired verdict of a headline row, in words."""
    parts = [f"{r.measure} {interval(r)} % of {r.n} scans"]
    if not math.isnan(r.error_cm):
        parts.append(f"{r.error} {r.error_cm:.3g} cm")
    if not math.isnan(r.cpu_ms):
        parts.append(f"CPU {r.cpu_ms:.3g} ms (median)")
    if r.verdict:
        parts.append(f"{r.verdict} {'of' if r.verdict == 'ahead' else 'with'} {r.next_matcher} "
                     f"(McNemar, Holm p = {r.p_holm:.2g})")
    return "; ".join(parts)


def headline_cell(r: HeadlineRow, run: str) -> Cell:
    """The cell of one headline row."""
    return Cell(r.value_pct, interval(r), cpu_text(r.cpu_ms), tooltip(r), is_best(r), run, r)


def _columns(rr: RunRows, modes: tuple[str, ...], short: bool) -> list[Column]:
    out = []
    for mode in modes:
        rows = [r for r in rr.rows if r.mode == mode]
        scopes = list(dict.fromkeys(r.scope for r in rows))
        if POOLED in scopes:
            scopes = [POOLED] + [s for s in scopes if s != POOLED]
        if short and scopes:
            scopes = scopes[:1]
        measure = {r.scope: r.measure for r in rows}
        cols = [Column(rr.name, mode, s, measure[s], kind=rr.kinds.get(s, "")) for s in scopes]
        if not short and cols and measure[cols[0].scope] != TRUTH_FREE:  # the first column's extras
            top, c0 = [r for r in rows if r.scope == cols[0].scope], cols[0]
            cols[1:1] = [Column(rr.name, mode, c0.scope, c0.measure, figure=f, kind=c0.kind)
                         for f in EXTRAS if any(math.isfinite(getattr(r, f)) for r in top)]
        out += cols
    return out


def extra_cell(r: HeadlineRow, run: str, figure: str) -> Cell | None:
    """The cell of one of a headline row's extra figures (:data:`EXTRAS`), or ``None`` (NaN)."""
    v = getattr(r, figure)
    if not math.isfinite(v):
        return None
    label, about, fmt = EXTRAS[figure]
    return Cell(v, fmt.format(v), "", f"{label}: {fmt.format(v)}, {about}", False, run, r)


def order(matchers: dict[str, tuple[int, int]]) -> list[str]:
    """Matchers by the first column they appear in, then by their rank there."""
    return sorted(matchers, key=lambda m: (*matchers[m], m))


def headline_board(page: Page, runs: dict[str, RunRows], short: bool = False) -> Board:
    """The page's leaderboard from the runs' headline rows (``short``: only each short run's top
    column, the README's table)."""
    columns: list[Column] = []
    cells: dict[tuple[str, str], Cell] = {}
    first: dict[str, tuple[int, int]] = {}
    for ref in page.runs:
        if short and not ref.short:
            continue
        rr = runs.get(ref.dir)
        if rr is None or not rr.rows:
            continue
        for col in _columns(rr, ref.modes, short):
            columns.append(col)
            for r in rr.rows:
                if (r.mode, r.scope) != (col.mode, col.scope):
                    continue
                if col.figure:
                    c = extra_cell(r, rr.name, col.figure)
                    if c is not None:
                        cells[(r.matcher, col.key)] = c
                    continue
                cells[(r.matcher, col.key)] = headline_cell(r, rr.name)
                first.setdefault(r.matcher, (len(columns) - 1, r.rank))
    return Board(page.key, page.title, columns, order(first), cells)


def unique_dirs(pages: list[Page]) -> list[str]:
    """Every run directory the pages name, once, in order."""
    return list(dict.fromkeys(r.dir for p in pages for r in p.runs))
