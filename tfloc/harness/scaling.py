"""The scaling study (``tfloc scaling``): how every matcher's CPU per scan grows with the map's
area, the scanner's beam count and the initial offset, and what its map preparation costs. This
module is the study's loop and its resume; the pieces are the configuration
(:mod:`~tfloc.harness.scaling_config`), the problem sets (:mod:`~tfloc.harness.scaling_levels`),
one level timed (:mod:`~tfloc.harness.scaling_level`), the memory probe
(:mod:`~tfloc.harness.memory`) and the matchers and fingerprint
(:mod:`~tfloc.harness.scaling_matchers`).

:func:`scaling_study` runs (or resumes) a study into a run directory
(:class:`~tfloc.io.rundir.RunDir`), the process pinned to one core with every library on one
thread. ``run.json``: ``config`` (``kind: "scaling"``, ``name``, the matchers, the success
thresholds, the study's fields under ``scaling``), the environment
(:func:`tfloc.harness.runner.environment`), the tile map as its one dataset, the fingerprint,
the ``command``, the ``levels`` and the ones ``done``, and one session per start (load averages,
cores, CPU and wall seconds). The typed rows (:mod:`tfloc.core.rows.timing`) go to
``scaling.csv``, ``prep.csv`` and ``skips.csv`` (through the store, :mod:`tfloc.io.tables`), each rewritten
atomically after every level before the level is recorded as done: a level cut off by a kill is
run again, never mixed. A directory of another configuration is refused with one line naming
what differs; ``regenerate`` starts it over, and also a complete study of the same one.
:func:`tfloc.report.scaling.render_scaling` derives the tables, the figure and the README from
the directory alone.
"""

from __future__ import annotations

import gc
import time
from pathlib import Path

import pandas as pd

from tfloc.core.jsonable import jsonable
from tfloc.core.matcher import Matcher
from tfloc.core.rows.timing import MAP, PrepRow, ScanRow, SkipRow
from tfloc.errors import ConfigError, ResultsError
from tfloc.evaluation.scaling import level_table, over_budget, slope_table
from tfloc.io.geojson import read_vector_map
from tfloc.io.rundir import RunDir
from tfloc.io.table import frame_of
from tfloc.io.tables import LEVELS, PREP, SCALING, SKIPS, SLOPES
from tfloc.maps.vector import VectorMap

from .pinning import pinned
from .runner import environment, load_average
from .scaling_config import THRESHOLDS, Log, Progress, StudyConfig
from .scaling_level import skipped_prep, time_level
from .scaling_levels import Level, study_levels
from .scaling_matchers import study_differences, study_fingerprint, study_matchers

KIND = "scaling"
#: the study's raw rows, and the record an older tfloc kept (removed when a study starts over)
RAW_FILES = tuple(t.name for t in (SCALING, PREP, SKIPS))
LEGACY = ("study.json",)
Rows = tuple[list[ScanRow], list[PrepRow], list[PrepRow], list[SkipRow]]  # scans, maps, preparations, skips


def scaling_study(cfg: StudyConfig, out: Path, regenerate: bool = False, progress: Progress | None = None,
                  log: Log = print, command: str = "") -> RunDir:
    """Run (or resume) the study of ``cfg`` into ``out`` (module notes) and return its run
    directory; the caller renders it (:func:`tfloc.report.scaling.render_scaling`).
    ``progress(done, total)`` is told of the (scan, matcher) pairs done; ``log`` gets one line
    per level, per matcher left out, and whether the study resumes or is already complete;
    ``command`` is recorded as the command line that makes it. Another configuration in ``out``
    is a :class:`ConfigError` unless ``regenerate``."""
    clock = time.process_time(), time.perf_counter()
    with pinned() as cores:
        return _study(cfg, RunDir(Path(out)), cores, log, progress, regenerate, command, clock)


def study_doc(cfg: StudyConfig, name: str, matchers: list[str], fp: dict, levels: list[Level],
              done: set[str], command: str) -> dict:
    """``run.json`` of a study but for its sessions (module notes)."""
    config = {"kind": KIND, "name": name, "matchers": [{"label": n, "name": n, "params": {}} for n in matchers],
              "success": THRESHOLDS.to_dict(), "scaling": jsonable(cfg)}
    return {"config": config, **environment(), "datasets": {Path(cfg.map_path).stem: cfg.map_path},
            "fingerprint": fp, "command": command, "levels": [lv.key for lv in levels],
            "done": [lv.key for lv in levels if lv.key in done]}


def _open(rd: RunDir, fp: dict, levels: list[Level], regenerate: bool) -> set[str]:
    """The levels the directory has done, after the configuration check: another configuration
    is refused (:class:`ConfigError`) unless ``regenerate``, which also starts a complete study
    over; a run of ``tfloc bench`` is always refused."""
    if not rd.run_json.exists() and not any((rd.path / f).exists() for f in (*RAW_FILES, *LEGACY)):
        return set()
    try:
        info = rd.info()
    except ResultsError:
        if not regenerate:
            raise
        info = None
    if info is not None and info.exists and info.kind != KIND:
        raise ConfigError(f"{rd.path} holds a run of tfloc {info.kind}, not a scaling study: choose another --out")
    diff = study_differences(info.fingerprint if info is not None else None, fp)
    if diff and not regenerate:
        more = f" (and {len(diff) - 3} more)" if len(diff) > 3 else ""
        raise ConfigError(f"{rd.path} holds a study of another configuration: {'; '.join(diff[:3])}{more}; "
                          "to start it over give --regenerate, to keep it choose another --out")
    done = set(info.done if info is not None else []) & {lv.key for lv in levels}
    if diff or (regenerate and len(done) == len(levels)):
        rd.discard(also=(*RAW_FILES, *LEGACY))
        return set()
    return done


def _done_rows(levels: list[Level], done: set[str], rd: RunDir) -> Rows:
    """The recorded rows of the levels done (scan, map, matcher preparation and skip rows); rows
    of a level cut off before ``run.json`` recorded it are dropped."""
    if not done:
        return [], [], [], []
    rows, prep, skips = (rd.read(t) for t in (SCALING, PREP, SKIPS))
    area = {(lv.kind, lv.tiling.tiles): lv.key for lv in levels if lv.axis == "area"}
    prep = [p for p in prep if area.get((p.kind, p.tiles)) in done]
    return ([r for r in rows if r.level_key in done], [p for p in prep if p.matcher == MAP],
            [p for p in prep if p.matcher != MAP], [s for s in skips if f"{s.axis}/{s.kind}/{s.level}" in done])


def _study(cfg: StudyConfig, rd: RunDir, cores: list[int], log: Log, progress: Progress | None,
           regenerate: bool, command: str, clock: tuple[float, float]) -> RunDir:
    """:func:`scaling_study` once pinned: the configuration check, ``run.json``, the levels."""
    tile = read_vector_map(cfg.map_path)
    matchers = study_matchers(cfg.matchers or None, log)
    fp = study_fingerprint(cfg, list(matchers))
    levels = study_levels(cfg, tile)
    done = _open(rd, fp, levels, regenerate)
    if all(lv.key in done for lv in levels):
        log(f"{rd.path}: already complete: 0 levels run (--regenerate runs it again)")
        return rd
    if done:
        log(f"{rd.path}: resuming: {len(done)} of {len(levels)} levels done by the same code and configuration")
    rd.make()
    state = _done_rows(levels, done, rd)
    doc = study_doc(cfg, rd.path.name, list(matchers), fp, levels, done, command)
    pairs = sum(len(lv.scans) for lv in levels) * len(matchers)
    pairs_done = sum(len(lv.scans) for lv in levels if lv.key in done) * len(matchers)
    rd.start_session(doc, pairs, pairs_done, load_average(), levels_done_before=len(done), git=doc["git"],
                     cores=cores)
    gc.freeze()  # the libraries' objects: every later gc.collect (memory probes) skips them
    try:
        _run_levels(cfg, tile, matchers, levels, done, state, rd, log, progress, clock)
    finally:
        gc.unfreeze()
    return rd


def _run_levels(cfg: StudyConfig, tile: VectorMap, matchers: dict[str, Matcher], levels: list[Level],
                done: set[str], state: Rows, rd: RunDir, log: Log, progress: Progress | None,
                clock: tuple[float, float]) -> None:
    """:func:`scaling_study`'s loop: every level not done, the budgets, the rows and then
    ``run.json``'s ``done`` written after each; the session's CPU and wall seconds counted from
    ``clock``."""
    rows, map_prep, prep, skips = state
    c0, w0 = clock
    total = sum(len(lv.scans) for lv in levels) * len(matchers)
    count = sum(len(lv.scans) for lv in levels if lv.key in done) * len(matchers)

    def step(n: int) -> None:
        nonlocal count
        count += n
        if progress is not None:
            progress(count, total)

    def spent() -> dict[str, float]:
        return {"wall_s": round(time.perf_counter() - w0, 1), "cpu_s": round(time.process_time() - c0, 1)}

    step(0)
    out_of_budget: dict[tuple[str, str, str], str] = {}   # (axis, kind, matcher) → why
    try:
        for lv in levels:
            if lv.key in done:   # a resumed level: its rows decide the budgets as when it ran
                _budgets(cfg, lv, [r for r in rows if r.level_key == lv.key],
                         [p for p in prep if lv.axis == "area" and p.kind == lv.kind and p.tiles == lv.tiling.tiles],
                         out_of_budget)
                continue
            active = {n: m for n, m in matchers.items() if (lv.axis, lv.kind, n) not in out_of_budget}
            for n in (n for n in matchers if n not in active):
                skips.append(SkipRow(lv.axis, lv.kind, lv.level, float(lv.size), n, out_of_budget[(lv.axis, lv.kind, n)]))
                if lv.axis == "area":
                    prep.append(skipped_prep(lv, n))
            step(len(lv.scans) * (len(matchers) - len(active)))
            if active:
                c1 = time.process_time()
                r, p, m = time_level(lv, tile, active, cfg, log, step)
                gc.collect()
                rows += r
                if lv.axis == "area":
                    prep += p
                    map_prep.append(m)
                med = _budgets(cfg, lv, r, p, out_of_budget)
                log(f"{lv.axis:6s} {lv.kind:6s} {lv.level:18s} {len(lv.scans)} scans × {len(active)} matchers: "
                    f"{time.process_time() - c1:6.1f} s CPU; median ms "
                    + ", ".join(f"{n} {v:.1f}" for n, v in med.items()))
            for table, data in ((SCALING, rows), (PREP, map_prep + prep), (SKIPS, skips)):
                rd.write(table, data)
            done.add(lv.key)
            rd.record_levels([x.key for x in levels if x.key in done], **spent())
    finally:
        rd.close_session(load_average(), **spent())


def _budgets(cfg: StudyConfig, lv: Level, rows: list[ScanRow], prep: list[PrepRow],
             out_of_budget: dict[tuple[str, str, str], str]) -> dict[str, float]:
    """Record the level's matchers over budget in ``out_of_budget``; returns their median CPU ms."""
    r, p = frame_of(rows, ScanRow), frame_of(prep, PrepRow)
    over = over_budget(r, p, lv.level, cfg.budget_ms, cfg.prep_budget_s if lv.axis == "area" else None)
    out_of_budget.update({(lv.axis, lv.kind, n): why for n, why in over.items()})
    return {n: float(v) for n, v in r.groupby("matcher", sort=False)["cpu_ms"].median().items()} if len(r) else {}


def derive_scaling(run_dir: Path) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """The scaling study's tables from its run directory alone: its rows (``scaling.csv``,
    ``prep.csv``, ``skips.csv``) and, derived from them and written, ``levels.csv`` and
    ``slopes.csv`` (:mod:`tfloc.evaluation.scaling`). A directory that holds no scaling study's
    ``run.json`` is a :class:`ResultsError`."""
    rd = RunDir(run_dir)
    if rd.info().kind != KIND:
        raise ResultsError(f"{rd.path}: no scaling study here (its run.json is missing or not of kind "
                           "'scaling'; run 'tfloc scaling' first)")
    rows, prep, skips = (rd.frame(t) for t in (SCALING, PREP, SKIPS))
    levels = level_table(rows)
    rd.write(LEVELS, levels)
    rd.write(SLOPES, slope_table(levels))
    return rows, prep, skips, rd.frame(LEVELS), rd.frame(SLOPES)
