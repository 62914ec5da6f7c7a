"""The cost page's two tables: CPU per scan or step (ms, median, one thread) of every matcher in
every run the other pages read (from the headline rows, and from the quiet side-by-side
re-timing ``timing.csv`` behind ``timing.md`` where the run has one), and the scaling study's
log–log slopes of CPU per scan against map area, beam count and initial offset (``slopes.csv``).
Lower is better; no cell is marked best (CPU has no paired test here). Pure: tables in, boards out."""

from __future__ import annotations

import math

import pandas as pd

from tfloc.core.rows.headline import POOLED
from tfloc.io.tables import SLOPES as SLOPES_TABLE

from .board import Board, Cell, Column, order
from .pages import COST, Page
from .rows import RunRows

SLOPES = "slopes"  #: the slopes board's key
SLOPES_CSV = SLOPES_TABLE.name  #: the scaling study's file that board reads

QUIET = "re-timing"
#: a run without a pooled CPU figure shows each dataset's if it has at most this many
MAX_SPLIT = 3


def _ms(v: float) -> str:
    return "—" if math.isnan(v) else f"{v:.3g}"


def cpu_board(pages: list[Page], runs: dict[str, RunRows], timing: dict[str, pd.DataFrame],
              marks: dict[str, str] | None = None) -> Board:
    """CPU ms per scan: per run and mode its pooled column where that has a CPU figure, else
    each dataset's (at most :data:`MAX_SPLIT`; the run's own page has the rest); then the run's
    quiet re-timing (``timing``: run → ``timing.csv`` rows), labelled with its contention mark
    (``marks``: run → :func:`tfloc.evaluation.contention.mark`, e.g. ``contended (×1.42 inflated)``)."""
    marks = marks or {}
    columns: list[Column] = []
    cells: dict[tuple[str, str], Cell] = {}
    first: dict[str, tuple[int, int]] = {}
    seen: set[str] = set()
    for p in pages:
        for ref in p.runs:
            rr = runs.get(ref.dir)
            if p.key == COST or ref.dir in seen or rr is None:
                continue
            seen.add(ref.dir)
            for mode in ref.modes:
                rows = [r for r in rr.rows if r.mode == mode]
                pooled = [r for r in rows if r.scope == POOLED and not math.isnan(r.cpu_ms)]
                scopes = {r.scope for r in rows if r.scope != POOLED}
                keep = pooled or ([r for r in rows if r.scope != POOLED] if len(scopes) <= MAX_SPLIT else [])
                for scope in dict.fromkeys(r.scope for r in keep):
                    col = Column(ref.dir, mode, scope, "CPU ms")
                    columns.append(col)
                    for r in (r for r in keep if r.scope == scope):
                        cells[(r.matcher, col.key)] = Cell(r.cpu_ms, _ms(r.cpu_ms), "", f"median CPU per "
                                                           f"{'step' if mode == 'sequence' else 'scan'}, "
                                                           f"{r.n} scans", False, ref.dir, r)
                        first.setdefault(r.matcher, (len(columns) - 1, 0))
            t = timing.get(ref.dir)
            if t is not None and not t.empty:
                note = marks.get(ref.dir, "")
                col = Column(ref.dir, QUIET, POOLED, "CPU ms", note=note)
                columns.append(col)
                for m, g in t.groupby("matcher", sort=False):
                    v = float(pd.to_numeric(g["cpu_ms"], errors="coerce").median())
                    cells[(str(m), col.key)] = Cell(v, _ms(v), "", f"median CPU of {len(g)} scans re-timed "
                                                    "side by side in one pinned process"
                                                    + (f", {note}" if note else ""), False, ref.dir)
                    first.setdefault(str(m), (len(columns) - 1, 0))
    for m, (i, _) in first.items():  # rows by their first column, cheapest first
        v = cells[(m, columns[i].key)].value
        first[m] = (i, 10**12 if math.isnan(v) else int(1000 * v))
    return Board("cpu", "CPU per scan (ms, median)", columns, order(first), cells, higher=False, unit="ms")


def slopes_board(slopes: dict[str, pd.DataFrame]) -> Board:
    """The scaling study's slopes (``slopes``: run → ``slopes.csv`` rows): one column per axis
    and map kind; a cell is the log–log slope of CPU per scan, below it first → last level (ms)."""
    columns: list[Column] = []
    cells: dict[tuple[str, str], Cell] = {}
    first: dict[str, tuple[int, int]] = {}
    for run, df in slopes.items():
        for (axis, kind), g in df.groupby(["axis", "kind"], sort=False):
            col = Column(run, "slope", f"{axis} ({kind})", "log–log slope")
            columns.append(col)
            for r in g.to_dict("records"):
                v = float(r["slope"])
                sub = f"{float(r['first_ms']):.3g} → {float(r['last_ms']):.3g} ms"
                title = (f"{axis} {float(r['first_size']):g} → {float(r['last_size']):g} over {int(r['levels'])} "
                         f"levels; {'grows' if str(r['grows']) == 'True' else 'does not grow'} by the study's rule")
                cells[(str(r["matcher"]), col.key)] = Cell(v, f"{v:.2f}", sub, title, False, run)
                first.setdefault(str(r["matcher"]), (len(columns) - 1, 0))
    return Board(SLOPES, "How CPU per scan grows (log–log slope)", columns, order(first), cells,
                 higher=False, unit="")
