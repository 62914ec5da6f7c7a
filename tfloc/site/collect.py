"""Everything the site shows, read from a results root once, each table through the store
(:class:`tfloc.io.rundir.RunDir`): each page's runs' headline rows (:mod:`tfloc.site.rows`), the
re-timings and the scaling slopes of the cost page, and the leaderboards and statements built
from them. With :mod:`tfloc.site.rows` (a run's rows) and :mod:`tfloc.site.runs` (its
``run.json`` and datasets), the only modules of the site that read a run directory; the
renderers take what it returns (a run's page reads its notes)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from tfloc.evaluation.contention import Contention, mark
from tfloc.io.rundir import RunDir
from tfloc.io.table import Table
from tfloc.io.tables import SELFASSESS, SLOPES, TIMING, TRACKING, VERDICT_AGREEMENT

from .advice import Statement, statements
from .board import Board, headline_board, unique_dirs
from .cost import cpu_board, slopes_board
from .pages import COST, Page, load_pages
from .rows import RunRows, run_rows
from .runs import run_info
from .targets import NATIVE_RUNS, SIMULATED_RUN, targets_markdown


@dataclass
class SiteData:
    """The pages, their runs' rows by directory, the boards by page key (``cost``: the CPU
    table, ``cost-slopes``: the scaling slopes; ``KEY-short``: the README's) and the statements."""

    root: Path
    pages: list[Page]
    runs: dict[str, RunRows]
    boards: dict[str, Board] = field(default_factory=dict)
    statements: list[Statement] = field(default_factory=list)
    targets: str = ""  #: the tracking targets, checked (Markdown; :mod:`tfloc.site.targets`)
    truth_free: str = ""  #: the truth-free verdict against the truth (Markdown; :mod:`tfloc.site.truthfree`)
    self_assessment: str = ""  #: every tracker's self-assessment (Markdown)


def _table(run_dir: Path, table: Table) -> pd.DataFrame | None:
    """``table`` of the run in ``run_dir`` through the store (None where it has none)."""
    df = RunDir(run_dir).frame(table)
    return None if df.empty else df


def collect(root: Path, quick: bool = False, pages: list[Page] | None = None) -> SiteData:
    """Read the results root ``root`` for ``pages`` (default: ``pages.toml``'s; ``quick``:
    ``make quick``'s runs) and build every board and statement."""
    root = Path(root)
    pages = pages if pages is not None else load_pages(quick=quick)
    runs = {d: run_rows(root, d) for d in unique_dirs(pages)}
    data = SiteData(root, pages, runs)
    timing = {d: t for d in runs if (t := _table(root / d, TIMING)) is not None}
    for p in pages:
        if p.key == COST:
            data.boards[COST] = cpu_board(pages, runs, timing, {d: timing_mark(root / d) for d in timing})
            slopes = {r.dir: s for r in p.runs if (s := _table(root / r.dir, SLOPES)) is not None}
            data.boards[f"{COST}-slopes"] = slopes_board(slopes)
            continue
        data.boards[p.key] = headline_board(p, runs)
        data.boards[f"{p.key}-short"] = headline_board(p, runs, short=True)
    data.statements = statements(data.boards)
    data.targets = _targets(root, runs)
    data.truth_free, data.self_assessment = _truth_free(root)
    return data


def _truth_free(root: Path) -> tuple[str, str]:
    """The truth-free blocks from the runs of :data:`tfloc.site.truthfree.RUNS`."""
    from tfloc.harness.config import load_study

    from .truthfree import DEV_STUDY, RUNS, agreement_markdown, selfassess_markdown

    agree = {r: t for r in RUNS if (t := _table(root / r, VERDICT_AGREEMENT)) is not None}
    assess = {r: t for r in RUNS if (t := _table(root / r, SELFASSESS)) is not None}
    dev = {d.name for d in load_study(DEV_STUDY).run.datasets} if Path(DEV_STUDY).is_file() else set()
    return agreement_markdown(agree, dev), selfassess_markdown(assess)


def timing_mark(run_dir: Path) -> str:
    """The contention mark of the run's timing pass (``contended (×f inflated)``; empty when quiet,
    not measured by an older pass, or the run's record is unreadable)."""
    timing = run_info(run_dir).timing   # (run.json's sessions are checked to be tables)
    return mark(Contention.from_record(timing.last_session.contention) if timing is not None else None)


def _reported(root: Path, runs: dict[str, RunRows], name: str) -> RunRows | None:
    rr = runs.get(name) or run_rows(root, name)
    return rr if rr.reported else None


def _targets(root: Path, runs: dict[str, RunRows]) -> str:
    """The targets block from the first native run with a headline and ``tracking.csv``."""
    native = None
    for name in NATIVE_RUNS:
        rr, tracking = _reported(root, runs, name), _table(root / name, TRACKING)
        if rr is not None and tracking is not None:
            native = (name, rr.rows, tracking)
            break
    sim = _reported(root, runs, SIMULATED_RUN)
    return targets_markdown(native, (SIMULATED_RUN, sim.rows, sim.kinds) if sim is not None else None)


def run_note(rr: RunRows | None, name: str, table: str | None = None) -> str:
    """Where a run's figures come from, or why it has none (Markdown inline); ``table``: the file
    a board reads instead of the headline (the scaling study's ``slopes.csv``)."""
    if rr is None or not rr.exists:
        return f"`results/{name}/`: not yet run"
    if table is not None:
        return f"`results/{name}/`: `{table}`"
    if not rr.reported:
        return f"`results/{name}/`: no headline yet (run `tfloc report results/{name}`)"
    return f"`results/{name}/`: `headline.csv`"
