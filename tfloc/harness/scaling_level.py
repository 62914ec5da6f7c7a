"""Timing one level of the scaling study: the map built, every matcher prepared on its own copy,
warmed up, then every scan's ``localize`` timed, the matchers interleaved.

Measurement under the timing pass's rules (:mod:`tfloc.harness.pinning`; the caller pins the
process): each matcher's ``prepare`` timed (CPU and wall s) with the memory it keeps and peaks at
(:class:`~tfloc.harness.memory.MemoryProbe`), then an untimed warm-up
(:func:`~tfloc.harness.workspace.warm` and ``warmup`` calls), then scan by scan every matcher once
in rotated order, timed by :func:`~tfloc.harness.workspace.timed_localize` with its system time
apart. Each matcher prepares its own copy of the map (:func:`fresh_copy`), so that no matcher's
preparation is paid for by another's cache. Rows are typed (:mod:`tfloc.core.rows.timing`);
success is :data:`~tfloc.harness.scaling_config.THRESHOLDS`'.
"""

from __future__ import annotations

import dataclasses
import math
import resource
from collections.abc import Callable

import numpy as np

from tfloc.core.matcher import Matcher
from tfloc.core.problem import Problem
from tfloc.core.result import Status, StatusKind
from tfloc.core.rows.timing import MAP, PrepRow, ScanRow
from tfloc.datasets.tiling import TileScan, Tiling, scan_ranges, tile_vector_map
from tfloc.maps.build import rasterize
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap

from .memory import MemoryProbe
from .pinning import rotated
from .scaling_config import THRESHOLDS, Log, StudyConfig
from .scaling_levels import Level
from .task import error_status
from .workspace import status_of, timed, timed_localize, warm


def _tiled(tile: VectorMap, tiling: Tiling, kind: str, resolution_m: float) -> tuple[VectorMap | GridMap, int]:
    vm = tile_vector_map(tile, tiling)
    return (rasterize(vm, resolution_m) if kind == "grid" else vm), len(vm.segments)


def build_map(tile: VectorMap, lv: Level, resolution_m: float) -> tuple[VectorMap | GridMap, PrepRow]:
    """The level's map (``tile`` repeated, rasterised at ``resolution_m`` metres for a grid) and
    its ``(map)`` preparation row: building it, timed by the harness's timer, and its memory."""
    with MemoryProbe() as mem:
        t = timed(_tiled, tile, lv.tiling, lv.kind, resolution_m)
        (m, segments), cpu_s, wall_s = t.estimate, t.cpu_s, t.wall_s
        del t
    cells = int(np.prod(m.shape)) if isinstance(m, GridMap) else 0
    return m, PrepRow(MAP, lv.kind, lv.tiling.tiles, lv.size, cells, segments, cpu_s, wall_s,
                      mem.retained_mb, mem.peak_mb, Status())


def fresh_copy(m: VectorMap | GridMap) -> VectorMap | GridMap:
    """A new map object over the same geometry (an empty per-map cache)."""
    return dataclasses.replace(m)


def _prepare(matcher: Matcher, problem: Problem) -> None:
    prepare = getattr(matcher, "prepare", None)
    if prepare is not None:
        prepare(problem)


def _system_s() -> float:
    """This process's system CPU time so far (seconds, ``getrusage``)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_stime


def scan_row(lv: Level, scan: TileScan, name: str, matcher: Matcher, problem: Problem, position: int) -> ScanRow:
    """One timed ``localize`` (:func:`~tfloc.harness.workspace.timed_localize`) as a row: CPU,
    system and wall ms, errors (m, °), success and status. A raising matcher is a row (``error:…``,
    no times), not a crash."""
    sys0 = _system_s()
    try:
        t = timed_localize(matcher, problem)
        est, status, cpu_s, wall_s = t.estimate, status_of(t.estimate), t.cpu_s, t.wall_s
    except Exception as exc:  # noqa: BLE001 - a raising matcher is a result
        est, status, cpu_s, wall_s = None, error_status(exc), math.nan, math.nan
    sys_s = _system_s() - sys0
    d, o = est.pose.error_to(scan.truth) if est is not None else (math.nan, math.nan)
    return ScanRow(name, lv.axis, lv.kind, lv.level, float(lv.size), lv.tiling.tiles, lv.laser.n_beams,
                   round(math.degrees(lv.laser.fov), 6), scan.scan_id, scan.offset_bin,
                   scan.initial.distance_to(scan.truth), position, 1000.0 * cpu_s, 1000.0 * sys_s,
                   1000.0 * wall_s, d, math.degrees(o), int(status.ok and THRESHOLDS.success(d, o)), status)


def skipped_prep(lv: Level, name: str) -> PrepRow:
    """The preparation row of a matcher not run at an area level (over budget)."""
    return PrepRow(name, lv.kind, lv.tiling.tiles, float(lv.size), 0, 0, math.nan, math.nan, math.nan, math.nan,
                   None)


def time_level(lv: Level, tile: VectorMap, matchers: dict[str, Matcher], cfg: StudyConfig, log: Log,
               step: Callable[[int], None] = lambda n: None) -> tuple[list[ScanRow], list[PrepRow], PrepRow]:
    """Prepare (timed, memory measured), warm up and time every matcher of ``matchers`` on the
    level's scans, interleaved. Returns the scan rows, the matchers' preparation rows and the
    map's own; ``step(n)`` is told of every ``n`` (scan, matcher) pairs done or given up."""
    base, map_row = build_map(tile, lv, cfg.resolution_m)
    ranges = [scan_ranges(tile, s, lv.laser) for s in lv.scans]
    shape = dict(kind=lv.kind, tiles=lv.tiling.tiles, size=float(lv.size), cells=map_row.cells,
                 segments=map_row.segments if isinstance(base, VectorMap) else 0)
    ready, prep = [], []
    for name, m in matchers.items():
        own = fresh_copy(base)
        problems = [Problem(own, lv.laser, r, s.initial, where=f"{lv.key}/{s.scan_id}")
                    for s, r in zip(lv.scans, ranges, strict=True)]
        try:
            with MemoryProbe() as mem:
                t = timed(_prepare, m, problems[0])
            warm(m, problems[0])                 # untimed: kernels, lazy structures
            for p in problems[:cfg.warmup]:
                m.localize(p)
        except Exception as exc:  # noqa: BLE001 - reported in prep.csv, the others go on
            log(f"{name} on {lv.key}: {type(exc).__name__}: {exc}")
            prep.append(PrepRow(name, **shape, prep_cpu_s=math.nan, prep_wall_s=math.nan, rss_delta_mb=math.nan,
                                peak_mb=math.nan, status=Status.of(StatusKind.ERROR, type(exc).__name__)))
            step(len(lv.scans))
            continue
        ready.append((name, m, problems))
        prep.append(PrepRow(name, **shape, prep_cpu_s=t.cpu_s, prep_wall_s=t.wall_s, rss_delta_mb=mem.retained_mb,
                            peak_mb=mem.peak_mb, status=Status()))
    rows = []
    for i, s in enumerate(lv.scans):
        for pos, (name, m, problems) in rotated(ready, i):
            rows.append(scan_row(lv, s, name, m, problems[i], pos))
        step(len(ready))
    return rows, prep, map_row
