"""The scaling study (issue 26, item 3): how every matcher's CPU per scan grows with the map's
area, the scanner's beam count and the initial offset, and what its map preparation costs.

Axes (each level one problem set, every matcher on the same scans):

* ``area``: the office floor (``data/maps/office-1.geojson``) tiled to about 300, 1 200, 5 000 and
  20 000 m² (:mod:`tfloc.datasets.tiling`), as a vector map and as a 5 cm grid
  (:func:`tfloc.maps.build.rasterize`); the scans are simulated in tile (0, 0), so they are the
  same at every size and only the map grows. LMS200 (181 beams).
* ``beams``: 181, 361, 721 beams (180° at 1°, 0.5°, 0.25°) and 1081 (270° at 0.25°), the same
  true and initial poses on the one-tile vector map.
* ``offset``: initial distance offsets in the protocol's bins 0–1, 1–2, 2–3 m (angle offsets in
  its three bins in turn), one-tile vector map, 181 beams.

Scans: true and initial poses from the protocol's sampler (:mod:`tfloc.datasets.synthetic`,
:mod:`tfloc.datasets.protocol`), scan k in offset cell k mod 9; ranges ray-cast on the tile plus the
default noise (1 cm); everything seeded (:data:`SEED`), so two runs give the same problems.

Measurement: one process pinned to one core, every library on one thread
(:func:`tfloc.harness.threads.limit_threads`). Each matcher gets its own copy of each map object
(so no matcher's preparation is paid by another's cache), then ``prepare(problem)`` (CPU time,
wall time, and the process's resident memory after it minus before it, psutil RSS after a
garbage collection: numba's and open3d's allocations included, unlike tracemalloc), then an
untimed warm-up (``score`` and ``localize`` on the first scan). Per-scan CPU time
(``time.process_time``: user + system) of ``localize`` alone, its system part apart
(``getrusage``: mostly the kernel handing out fresh pages for large temporary arrays), matchers interleaved scan by scan (the order
rotated by one per scan). Success = ≤ 10 cm and ≤ 2° (:class:`tfloc.evaluation.outcome.Thresholds`).

Bounds: a matcher whose median CPU at a level exceeds ``budget_ms``, or whose preparation
exceeded ``prep_budget_s``, is not run at the larger levels of that axis and map kind (the README
says so). Writes ``OUT/scaling.csv``, ``OUT/prep.csv``, ``OUT/levels.csv``, ``OUT/slopes.csv``,
``OUT/README.md``, ``OUT/scaling.png`` and ``OUT/study.json``.

    python scripts/scaling.py                      # the full study → results/scaling/
    python scripts/scaling.py --quick              # the make-bench subsample → results/scaling-quick/
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import os
import platform
import resource
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd

from tfloc.core.laser import LaserSpec
from tfloc.core.matcher import available_matchers, get_matcher, solves_global
from tfloc.core.pose import Pose, angdiff
from tfloc.core.problem import Problem
from tfloc.core.tracker import has_single_scan_mode
from tfloc.datasets.noise import NoiseModel
from tfloc.datasets.protocol import strata
from tfloc.datasets.synthetic import sample_pose_pair
from tfloc.datasets.tiling import Tiling, tile_vector_map, tiling_for_area
from tfloc.errors import ConfigError, LibraryMissingError, TflocError
from tfloc.evaluation.outcome import Thresholds
from tfloc.evaluation.scaling import (
    PREP_COLUMNS,
    SCAN_COLUMNS,
    level_table,
    prep_slope_table,
    slope_table,
)
from tfloc.harness.threads import limit_threads
from tfloc.io.geojson import read_vector_map
from tfloc.maps.build import rasterize
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap
from tfloc.report.scaling import write_figure, write_readme

ROOT = Path(__file__).resolve().parents[1]
SEED = 20261201
OFFSET_BINS = ("0-1 m", "1-2 m", "2-3 m")
OFFSET_MID_M = (0.5, 1.5, 2.5)
THRESHOLDS = Thresholds()  # success: ≤ 10 cm and ≤ 2°


@dataclass(frozen=True)
class StudyConfig:
    """What the study runs (sizes in m², beams as (field of view °, resolution °), budgets)."""

    map_path: str = "data/maps/office-1.geojson"
    areas_m2: tuple[float, ...] = (300.0, 1200.0, 5000.0, 20000.0)
    kinds: tuple[str, ...] = ("vector", "grid")
    lasers: tuple[tuple[float, float], ...] = ((180.0, 1.0), (180.0, 0.5), (180.0, 0.25), (270.0, 0.25))
    max_range_m: float = 10.0
    resolution_m: float = 0.05
    scans_per_level: int = 45          # area and beam axes: 5 per offset cell
    scans_per_offset_bin: int = 30     # offset axis: 10 per cell of each distance bin
    matchers: tuple[str, ...] = ()     # () = every registered matcher
    budget_ms: float = 250.0
    prep_budget_s: float = 120.0
    warmup: int = 1
    seed: int = SEED
    axes: tuple[str, ...] = ("area", "beams", "offset")

    @classmethod
    def quick(cls) -> StudyConfig:
        """The ``make bench`` subsample: every axis and level, 9 scans per level (one per offset
        cell), 3 per offset cell on the offset axis, tighter budgets."""
        return cls(scans_per_level=9, scans_per_offset_bin=9, budget_ms=150.0, prep_budget_s=60.0)


@dataclass(frozen=True)
class SimScan:
    """One simulated scan: id, offset cell, true and initial poses, and the seed of its noise."""

    scan_id: str
    cell: str
    truth: Pose
    initial: Pose
    noise_seed: int

    @property
    def offset_bin(self) -> str:
        return OFFSET_BINS[int(self.cell[1]) - 1]


@dataclass
class Level:
    """One problem set: an axis, a map kind, a level label, its x (``size``) and how to build it."""

    axis: str
    kind: str
    level: str
    size: float
    laser: LaserSpec
    scans: list[SimScan]
    tile: VectorMap
    make_map: Callable[[], VectorMap | GridMap]
    tiles: int = 1
    info: dict = field(default_factory=dict)


# -- problems -----------------------------------------------------------------------------------
def laser_of(fov_deg: float, resolution_deg: float, max_range_m: float) -> LaserSpec:
    """A laser centred on the heading: 180° at 1° is the LMS200 (181 beams)."""
    return LaserSpec.from_degrees(max_range_m, fov_deg, resolution_deg)


def simulate_poses(tile: VectorMap, cells: Sequence[int], seed: int, prefix: str) -> list[SimScan]:
    """One scan per entry of ``cells`` (indices into the protocol's 3 × 3 strata), seeded."""
    rng = np.random.default_rng(seed)
    cs = strata()
    out = []
    for k, c in enumerate(cells):
        truth, init = sample_pose_pair(tile, cs[c], rng)
        out.append(SimScan(f"{prefix}{k:03d}", cs[c].label, truth, init, int(rng.integers(2**31))))
    return out


def ranges_of(tile: VectorMap, scan: SimScan, laser: LaserSpec) -> np.ndarray:
    """The scan's ranges (metres) for ``laser``: ray-cast on ``tile`` at the truth, plus noise
    from the scan's own seed (so a scan does not depend on which others are simulated)."""
    return NoiseModel().apply(tile.raycast(scan.truth, laser), laser, np.random.default_rng(scan.noise_seed))


def fresh_copy(m: VectorMap | GridMap) -> VectorMap | GridMap:
    """A new map object over the same geometry (an empty per-map cache)."""
    if isinstance(m, GridMap):
        return GridMap(m.occupancy, m.resolution, m.origin, m.occupied_thresh, m.free_thresh, m.name)
    return VectorMap(walls=m.walls, obstacles=m.obstacles, outline=m.outline, name=m.name, region=m.region)


def rss_mb() -> float:
    """This process's resident memory (MB, psutil) after a garbage collection and
    ``malloc_trim(0)`` (glibc returns its free heap pages to the OS), so that memory freed earlier
    and kept by the allocator does not hide or inflate what a step keeps."""
    import psutil

    gc.collect()
    _malloc_trim()
    return psutil.Process().memory_info().rss / 2**20


def _malloc_trim() -> None:
    try:
        import ctypes

        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


def reset_peak() -> bool:
    """Reset this process's peak resident memory (Linux: ``/proc/self/clear_refs`` ← 5)."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return True
    except OSError:
        return False


def peak_mb() -> float:
    """This process's peak resident memory since :func:`reset_peak` (MB; VmHWM), NaN if unknown."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return math.nan


class MemoryProbe:
    """CPU and wall time, retained and peak resident memory (MB) of a block of code:
    ``with MemoryProbe() as m: ...`` then ``m.cpu_s``, ``m.wall_s``, ``m.retained_mb``,
    ``m.peak_mb`` (the peak above the memory before; NaN where the OS cannot tell)."""

    def __enter__(self) -> MemoryProbe:
        self._r0 = rss_mb()
        self._peak = reset_peak()
        self._c0, self._w0 = time.process_time(), time.perf_counter()
        return self

    def __exit__(self, *exc) -> None:
        self.cpu_s = time.process_time() - self._c0
        self.wall_s = time.perf_counter() - self._w0
        self.peak_mb = peak_mb() - self._r0 if self._peak else math.nan
        self.retained_mb = rss_mb() - self._r0


def build_levels(cfg: StudyConfig, tile: VectorMap) -> tuple[list[Level], list[dict]]:
    """Every problem set of the study, and the ``(map)`` preparation rows (building each map:
    CPU time and memory)."""
    lms = laser_of(180.0, 1.0, cfg.max_range_m)
    levels, prep = [], []
    if "area" in cfg.axes:
        scans = simulate_poses(tile, [k % 9 for k in range(cfg.scans_per_level)], cfg.seed, "a")
        for kind in cfg.kinds:
            for area in cfg.areas_m2:
                t = tiling_for_area(tile, area)
                levels.append(Level("area", kind, f"{t.nx}x{t.ny}", t.extent_m2, lms, scans, tile,
                                    _map_builder(tile, t, kind, cfg.resolution_m, prep), t.tiles))
    if "beams" in cfg.axes:
        scans = simulate_poses(tile, [k % 9 for k in range(cfg.scans_per_level)], cfg.seed + 1, "b")
        one = tile_vector_map(tile, tiling_for_area(tile, 1.0))
        for fov, res in cfg.lasers:
            laser = laser_of(fov, res, cfg.max_range_m)
            levels.append(Level("beams", "vector", f"{laser.n_beams} ({fov:g}°/{res:g}°)", laser.n_beams,
                                laser, scans, tile, lambda one=one: one))
    if "offset" in cfg.axes:
        n = cfg.scans_per_offset_bin
        for b, (label, mid) in enumerate(zip(OFFSET_BINS, OFFSET_MID_M, strict=True)):
            scans = simulate_poses(tile, [3 * b + k % 3 for k in range(n)], cfg.seed + 2 + b, f"o{b}-")
            one = tile_vector_map(tile, tiling_for_area(tile, 1.0))
            levels.append(Level("offset", "vector", label, mid, lms, scans, tile, lambda one=one: one))
    return levels, prep


def _map_builder(tile: VectorMap, t: Tiling, kind: str, resolution: float, prep: list[dict]):
    """A function building the tiled map once (timed, its memory measured: a ``(map)`` row)."""
    box: dict = {}

    def build() -> VectorMap | GridMap:
        if "map" not in box:
            with MemoryProbe() as probe:
                vm = tile_vector_map(tile, t)
                segs = len(vm.segments)
                m = rasterize(vm, resolution) if kind == "grid" else vm
                cells = int(np.prod(m.shape)) if kind == "grid" else 0
                del vm
            prep.append({"matcher": "(map)", "kind": kind, "tiles": t.tiles, "size": t.extent_m2,
                         "cells": cells, "segments": segs, "prep_cpu_s": probe.cpu_s,
                         "prep_wall_s": probe.wall_s, "rss_delta_mb": probe.retained_mb,
                         "peak_mb": probe.peak_mb, "status": "ok"})
            box["map"] = m
        return box["map"]

    build.release = box.clear  # type: ignore[attr-defined]
    return build


# -- measurement --------------------------------------------------------------------------------
def success_of(est_pose: Pose, truth: Pose, thr: Thresholds = THRESHOLDS) -> tuple[float, float, bool]:
    """Distance error (m), orientation error (°) and success of an answer."""
    d, o = est_pose.distance_to(truth), abs(angdiff(est_pose.theta, truth.theta))
    ok = est_pose.is_finite() and bool(thr.success(d, o))
    return d, math.degrees(o), ok


def prepare_timed(matcher, problem: Problem) -> MemoryProbe:
    """``matcher.prepare(problem)`` if it has one, measured (:class:`MemoryProbe`)."""
    prepare = getattr(matcher, "prepare", None)
    with MemoryProbe() as probe:
        if prepare is not None:
            prepare(problem)
    return probe


def run_level(lv: Level, matchers: dict[str, object], log: Callable[[str], None],
              warmup: int = 1) -> tuple[list[dict], list[dict]]:
    """Prepare (timed), warm up and time every matcher of ``matchers`` on the level's scans,
    interleaved. Returns the per-scan rows and the per-matcher preparation rows."""
    base = lv.make_map()
    ranges = [ranges_of(lv.tile, s, lv.laser) for s in lv.scans]
    names = []
    maps, problems, prep = {}, {}, []
    for name in matchers:
        m = maps[name] = fresh_copy(base)
        problems[name] = [Problem(m, lv.laser, r, s.initial, where=f"{lv.axis}/{lv.level}/{s.scan_id}")
                          for s, r in zip(lv.scans, ranges, strict=True)]
        row = {"matcher": name, "kind": lv.kind, "tiles": lv.tiles, "size": lv.size,
               "cells": int(np.prod(base.shape)) if isinstance(base, GridMap) else 0,
               "segments": len(base.segments) if isinstance(base, VectorMap) else 0}
        try:
            probe = prepare_timed(matchers[name], problems[name][0])
            p0 = problems[name][0]
            if hasattr(matchers[name], "score"):  # odometry has no objective
                matchers[name].score(p0, p0.initial)  # untimed warm-up: kernels, lazy structures
            for p in problems[name][:warmup]:
                matchers[name].localize(p)
        except Exception as exc:  # noqa: BLE001 - reported in prep.csv, the others go on
            log(f"{name} on {lv.axis}/{lv.kind}/{lv.level}: {type(exc).__name__}: {exc}")
            prep.append({**row, "prep_cpu_s": math.nan, "prep_wall_s": math.nan, "rss_delta_mb": math.nan,
                         "peak_mb": math.nan, "status": f"error:{type(exc).__name__}"})
            continue
        names.append(name)
        prep.append({**row, "prep_cpu_s": probe.cpu_s, "prep_wall_s": probe.wall_s,
                     "rss_delta_mb": probe.retained_mb, "peak_mb": probe.peak_mb, "status": "ok"})
    rows = []
    k = len(names)
    for i, s in enumerate(lv.scans):
        for pos in range(k):
            name = names[(i + pos) % k]
            problem = problems[name][i]
            u0 = resource.getrusage(resource.RUSAGE_SELF).ru_stime
            w0, c0 = time.perf_counter(), time.process_time()
            try:
                est = matchers[name].localize(problem)
                status = "failed" if est.info.get("status") == "no-answer" else "ok"
            except Exception as exc:  # noqa: BLE001 - a raising matcher is a result, not a crash
                est, status = None, f"error:{type(exc).__name__}: {exc}"[:200]
            cpu, wall = time.process_time() - c0, time.perf_counter() - w0
            sys_s = resource.getrusage(resource.RUSAGE_SELF).ru_stime - u0
            d, o, ok = success_of(est.pose, s.truth) if est is not None else (math.nan, math.nan, False)
            ok = ok and status == "ok"
            rows.append({"matcher": name, "axis": lv.axis, "kind": lv.kind, "level": lv.level,
                         "size": lv.size, "tiles": lv.tiles, "beams": lv.laser.n_beams,
                         "fov_deg": round(math.degrees(lv.laser.fov), 6), "scan_id": s.scan_id,
                         "offset_bin": s.offset_bin, "init_dist_m": s.initial.distance_to(s.truth),
                         "position": pos, "cpu_ms": 1000.0 * cpu, "sys_ms": 1000.0 * sys_s,
                         "wall_ms": 1000.0 * wall,
                         "dist_err_m": d, "orient_err_deg": o, "success": int(ok), "status": status})
    del maps, problems
    gc.collect()
    return rows, prep


def build_matchers(names: Sequence[str] | None, log: Callable[[str], None]) -> dict[str, object]:
    """Every named matcher with its defaults (default: every registered single-scan local
    matcher); one whose library is missing is left out (logged).

    By default a tracker without a single-scan mode (amcl, tf-plus-recover: no ``localize`` of
    one scan from a guess), ``odometry`` (no objective: it answers its guess at no cost) and a
    global matcher (tf-global, bnb-global) are left out: the study's problems are local ones, and a global matcher's cost against the area is
    its own axis, measured per 100 m² of free space in ``results/global`` (issue 24). Named on
    the command line, they run (a global matcher then answers the local problem its own way)."""
    chosen = names is not None
    out = {}
    for name in names if chosen else available_matchers():
        try:
            m = get_matcher(name)
        except LibraryMissingError as exc:
            log(f"left out: {exc}")
            continue
        why = ("a global matcher" if solves_global(m) else "no single-scan mode" if not has_single_scan_mode(m)
               else "no objective: it answers its guess" if not hasattr(m, "score") else "")
        if not chosen and why:
            log(f"left out: {name} ({why})")
            continue
        out[name] = m
    return out


def run_study(cfg: StudyConfig, log: Callable[[str], None] = print) -> dict:
    """Run every level of the study; returns the rows, preparation rows, skips and provenance."""
    tile = read_vector_map(ROOT / cfg.map_path if not Path(cfg.map_path).is_absolute() else cfg.map_path)
    matchers = build_matchers(cfg.matchers or None, log)
    gc.freeze()  # the libraries' objects: every later gc.collect (memory probes) skips them
    try:
        return _run_levels(cfg, tile, matchers, log)
    finally:
        gc.unfreeze()


def _run_levels(cfg: StudyConfig, tile: VectorMap, matchers: dict[str, object],
                log: Callable[[str], None]) -> dict:
    """:func:`run_study`'s loop over the levels, with the budgets."""
    levels, map_prep = build_levels(cfg, tile)
    rows, prep, skips = [], [], []
    out_of_budget: dict[tuple[str, str, str], str] = {}   # (axis, kind, matcher) → why
    for lv in levels:
        active = {n: m for n, m in matchers.items() if (lv.axis, lv.kind, n) not in out_of_budget}
        for n in matchers:
            if n not in active:
                skips.append({"axis": lv.axis, "kind": lv.kind, "level": lv.level, "size": lv.size,
                              "matcher": n, "why": out_of_budget[(lv.axis, lv.kind, n)]})
                if lv.axis == "area":
                    prep.append({"matcher": n, "kind": lv.kind, "tiles": lv.tiles, "size": lv.size,
                                 "cells": 0, "segments": 0, "prep_cpu_s": math.nan, "prep_wall_s": math.nan,
                                 "rss_delta_mb": math.nan, "peak_mb": math.nan, "status": "skipped"})
        if not active:
            continue
        c0 = time.process_time()
        r, p = run_level(lv, active, log, cfg.warmup)
        rows += r
        if lv.axis == "area":
            prep += p
        release = getattr(lv.make_map, "release", None)
        if release is not None:
            release()
        gc.collect()
        med = pd.DataFrame(r, columns=SCAN_COLUMNS).groupby("matcher")["cpu_ms"].median()
        for pr in p:
            n = pr["matcher"]
            if n not in med.index:
                continue
            if med[n] > cfg.budget_ms:
                out_of_budget[(lv.axis, lv.kind, n)] = f"median {med[n]:.0f} ms > {cfg.budget_ms:g} ms at {lv.level}"
            elif lv.axis == "area" and pr["prep_cpu_s"] > cfg.prep_budget_s:
                out_of_budget[(lv.axis, lv.kind, n)] = (f"prepare {pr['prep_cpu_s']:.0f} s > "
                                                        f"{cfg.prep_budget_s:g} s at {lv.level}")
        log(f"{lv.axis:6s} {lv.kind:6s} {lv.level:18s} {len(lv.scans)} scans × {len(active)} matchers: "
            f"{time.process_time() - c0:6.1f} s CPU; median ms " +
            ", ".join(f"{n} {med[n]:.1f}" for n in med.index))
    return {"rows": pd.DataFrame(rows, columns=SCAN_COLUMNS),
            "prep": pd.DataFrame(map_prep + prep, columns=PREP_COLUMNS),
            "skips": pd.DataFrame(skips, columns=["axis", "kind", "level", "size", "matcher", "why"]),
            "matchers": list(matchers)}


def pin_one_core() -> list[int]:
    """Pin this process to the last core it may run on; returns the cores it runs on."""
    if not hasattr(os, "sched_setaffinity"):
        return []
    cores = sorted(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cores[-1]})
    return sorted(os.sched_getaffinity(0))


def write_results(out: Path, result: dict, cfg: StudyConfig, provenance: dict) -> None:
    """The study's raw rows (``scaling.csv``, ``prep.csv``, ``skips.csv``, ``study.json``) into
    ``out``, then everything derived from them (:func:`render`)."""
    out.mkdir(parents=True, exist_ok=True)
    result["rows"].to_csv(out / "scaling.csv", index=False, float_format="%.6g")
    result["prep"].to_csv(out / "prep.csv", index=False, float_format="%.6g")
    result["skips"].to_csv(out / "skips.csv", index=False, float_format="%.6g")
    (out / "study.json").write_text(json.dumps({"config": asdict(cfg), **provenance}, indent=1) + "\n")
    render(out)


def render(out: Path) -> None:
    """``levels.csv``, ``slopes.csv``, ``scaling.png`` and ``README.md`` from the raw files in
    ``out`` (so the tables and text can be redrawn without measuring again)."""
    try:
        rows = pd.read_csv(out / "scaling.csv")
        prep = pd.read_csv(out / "prep.csv")
        skips = pd.read_csv(out / "skips.csv")
        doc = json.loads((out / "study.json").read_text())
    except (OSError, ValueError) as exc:
        raise ConfigError(f"{out}: cannot read the study's raw files ({exc}); run the study first") from None
    levels = level_table(rows)
    slopes = slope_table(levels)
    levels.to_csv(out / "levels.csv", index=False, float_format="%.6g")
    slopes.to_csv(out / "slopes.csv", index=False, float_format="%.4g")
    write_figure(out / "scaling.png", levels, slopes, prep)
    config = doc.pop("config", {})
    write_readme(out / "README.md", rows, levels, slopes, prep, prep_slope_table(prep), skips, config,
                 doc)


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="the make-bench subsample (StudyConfig.quick)")
    ap.add_argument("--out", type=Path, default=None, help="results folder (default results/scaling[-quick])")
    ap.add_argument("--matchers", nargs="*", default=None,
                    help="matcher names (default: every registered single-scan local matcher)")
    ap.add_argument("--axes", nargs="*", default=None, choices=("area", "beams", "offset"))
    ap.add_argument("--scans", type=int, default=None, help="scans per level (area and beam axes)")
    ap.add_argument("--render", action="store_true",
                    help="only redraw the tables, figure and README from the raw files in --out")
    args = ap.parse_args(argv)
    cfg = StudyConfig.quick() if args.quick else StudyConfig()
    if args.matchers:
        cfg = replace(cfg, matchers=tuple(args.matchers))
    if args.axes:
        cfg = replace(cfg, axes=tuple(args.axes))
    if args.scans:
        cfg = replace(cfg, scans_per_level=args.scans)
    out = args.out or ROOT / "results" / ("scaling-quick" if args.quick else "scaling")
    try:
        if args.render:
            render(out)
            print(f"wrote {out}/README.md")
            return 0
        cores = pin_one_core()
        limit_threads(1)
        started, load0, w0 = time.strftime("%Y-%m-%dT%H:%M:%S%z"), os.getloadavg(), time.perf_counter()
        result = run_study(cfg, lambda s: print(s, flush=True))
        provenance = {"command": "make scaling-quick" if args.quick else "make scaling",
                      "started": started, "wall_s": round(time.perf_counter() - w0, 1),
                      "cpu_s": round(time.process_time(), 1),
                      "loadavg_start": [round(x, 2) for x in load0],
                      "loadavg_end": [round(x, 2) for x in os.getloadavg()], "cores": cores,
                      "cpu": _cpu_model(), "python": platform.python_version(),
                      "machine": platform.machine(), "matchers": result["matchers"]}
        write_results(out, result, cfg, provenance)
    except TflocError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {out}/README.md")
    return 0


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


if __name__ == "__main__":
    sys.exit(main())
