"""The scaling study: how every matcher's CPU per scan grows with the map's area, the scanner's
beam count and the initial offset, and what its map preparation costs (``tfloc scaling``).

Axes (each level one problem set, every matcher on the same scans):

* ``area``: the office floor (``data/maps/office-1.geojson``) tiled to about 300, 1 200, 5 000 and
  20 000 m² (:mod:`tfloc.datasets.tiling`), as a vector map and as a 5 cm grid
  (:func:`tfloc.maps.build.rasterize`); the scans are simulated in tile (0, 0), so they are the
  same at every size and only the map grows. LMS200 (181 beams).
* ``beams``: 181, 361, 721 beams (180° at 1°, 0.5°, 0.25°) and 1081 (270° at 0.25°), the same
  true and initial poses on the one-tile vector map.
* ``offset``: initial distance offsets in the protocol's bins 0–1, 1–2, 2–3 m (angle offsets in
  its three bins in turn), one-tile vector map, 181 beams.

Scans: :func:`tfloc.datasets.tiling.tile_scans`, ray-cast on the tile plus 1 cm noise, seeded
(:data:`SEED`). Measurement under the timing pass's rules (:mod:`tfloc.harness.timing`): one
pinned process, one thread per library, matchers interleaved scan by scan in rotated order, each
with its own copy of each map. ``prepare`` is timed (CPU, wall, resident and peak memory:
:class:`MemoryProbe`), then an untimed warm-up, then every ``localize``
(:func:`~tfloc.harness.workspace.timed_localize`, its system time apart). Success:
:class:`~tfloc.core.thresholds.Thresholds`.

Budgets: a matcher over ``budget_ms`` (median CPU) or ``prep_budget_s`` at a level is not run at
the larger levels of that axis and map kind (:func:`tfloc.evaluation.scaling.over_budget`).

The output directory (:func:`run_study`) holds ``study.json`` (configuration, fingerprint,
versions, commit, machine, sessions, levels done) and the raw rows ``scaling.csv``, ``prep.csv``
and ``skips.csv``, rewritten atomically after every level: an interrupted study resumes, a
directory of another configuration is refused.
:func:`tfloc.report.scaling.render` derives the tables, the figure and the README from them.
"""

from __future__ import annotations

import dataclasses
import gc
import hashlib
import json
import math
import platform
import resource
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from tfloc.core.laser import LaserSpec
from tfloc.core.matcher import Matcher, available_matchers, get_matcher, solves_global
from tfloc.core.problem import Problem
from tfloc.core.thresholds import Thresholds
from tfloc.core.tracker import has_single_scan_mode
from tfloc.datasets.tiling import (
    TileScan,
    Tiling,
    scan_ranges,
    tile_scans,
    tile_vector_map,
    tiling_for_area,
)
from tfloc.errors import ConfigError, LibraryMissingError, ResultsError
from tfloc.evaluation.scaling import PREP_COLUMNS, SCAN_COLUMNS, SKIP_COLUMNS, over_budget
from tfloc.io.atomic import replace_atomically
from tfloc.io.geojson import read_vector_map
from tfloc.maps.build import rasterize
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap

from .config import MatcherSpec
from .fingerprint import differences
from .identity import tfloc_code
from .preflight import build_matcher
from .runner import environment, load_average
from .pinning import pinned, rotated
from .workspace import status_of, timed, timed_localize, warm

SEED = 20261201
AXES = ("area", "beams", "offset")
KINDS = ("vector", "grid")
OFFSET_BINS = ("0-1 m", "1-2 m", "2-3 m")
OFFSET_MID_M = (0.5, 1.5, 2.5)
THRESHOLDS = Thresholds()  # success: ≤ 10 cm and ≤ 2°
STUDY_JSON, SCAN_CSV, PREP_CSV, SKIPS_CSV = "study.json", "scaling.csv", "prep.csv", "skips.csv"
Log = Callable[[str], None]
Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class StudyConfig:
    """What the study runs: the tile map, sizes (m²), map kinds, lasers as (field of view °,
    resolution °), range (m), grid resolution (m), scans per level, matchers (``()``: every
    registered single-scan local matcher), budgets (ms per scan, s of preparation), warm-up calls,
    seed and axes. Every field decides rows: all of it is the study's fingerprint."""

    map_path: str = "data/maps/office-1.geojson"
    areas_m2: tuple[float, ...] = (300.0, 1200.0, 5000.0, 20000.0)
    kinds: tuple[str, ...] = KINDS
    lasers: tuple[tuple[float, float], ...] = ((180.0, 1.0), (180.0, 0.5), (180.0, 0.25), (270.0, 0.25))
    max_range_m: float = 10.0
    resolution_m: float = 0.05
    scans_per_level: int = 45          # area and beam axes: 5 per offset cell
    scans_per_offset_bin: int = 30     # offset axis: 10 per cell of each distance bin
    matchers: tuple[str, ...] = ()
    budget_ms: float = 250.0
    prep_budget_s: float = 120.0
    warmup: int = 1
    seed: int = SEED
    axes: tuple[str, ...] = AXES

    def __post_init__(self) -> None:
        bad = ([f"axis {a!r}" for a in self.axes if a not in AXES] + ([] if self.axes else ["axes (none)"])
               + [f"map kind {k!r}" for k in self.kinds if k not in KINDS]
               + [f"{n} {v!r} (must be ≥ 1)" for n, v in (("scans per level", self.scans_per_level),
                                                          ("scans per offset bin", self.scans_per_offset_bin))
                  if v < 1]
               + [f"{n} {v!r} (must be > 0)" for n, v in (("range", self.max_range_m),
                                                          ("grid resolution", self.resolution_m)) if not v > 0]
               + ([f"warm-up {self.warmup!r} (must be ≥ 0)"] if self.warmup < 0 else []))
        if bad:
            raise ConfigError("scaling study: bad " + ", ".join(bad) + f" (axes: {', '.join(AXES)}; "
                              f"kinds: {', '.join(KINDS)})")

    @classmethod
    def quick(cls) -> StudyConfig:
        """The ``make bench`` subsample: every axis and level, 9 scans per level (one per offset
        cell), 9 per offset bin (3 per cell), tighter budgets."""
        return cls(scans_per_level=9, scans_per_offset_bin=9, budget_ms=150.0, prep_budget_s=60.0)


@dataclass(frozen=True)
class Level:
    """One problem set: its axis, map kind, label, x (``size``: m², beams or metres), laser,
    scans and tiling of the map."""

    axis: str
    kind: str
    level: str
    size: float
    laser: LaserSpec
    scans: tuple[TileScan, ...]
    tiling: Tiling

    @property
    def key(self) -> str:
        """``axis/kind/level``: the level's name in ``study.json``."""
        return f"{self.axis}/{self.kind}/{self.level}"


def laser_of(fov_deg: float, resolution_deg: float, max_range_m: float) -> LaserSpec:
    """A laser centred on the heading: 180° at 1° is the LMS200 (181 beams)."""
    return LaserSpec.from_degrees(max_range_m, fov_deg, resolution_deg)


def study_levels(cfg: StudyConfig, tile: VectorMap) -> list[Level]:
    """Every problem set of the study, in the order it runs (area, beams, offset); sizes that
    round to the same tiling are one level."""
    lms = laser_of(180.0, 1.0, cfg.max_range_m)
    one = tiling_for_area(tile, 1.0)
    levels: list[Level] = []
    if "area" in cfg.axes:
        scans = tile_scans(tile, [k % 9 for k in range(cfg.scans_per_level)], cfg.seed, "a")
        tilings = list(dict.fromkeys(tiling_for_area(tile, a) for a in cfg.areas_m2))
        levels += [Level("area", kind, f"{t.nx}x{t.ny}", t.extent_m2, lms, scans, t)
                   for kind in cfg.kinds for t in tilings]
    if "beams" in cfg.axes:
        scans = tile_scans(tile, [k % 9 for k in range(cfg.scans_per_level)], cfg.seed + 1, "b")
        for fov, res in cfg.lasers:
            laser = laser_of(fov, res, cfg.max_range_m)
            levels.append(Level("beams", "vector", f"{laser.n_beams} ({fov:g}°/{res:g}°)", laser.n_beams,
                                laser, scans, one))
    if "offset" in cfg.axes:
        n = cfg.scans_per_offset_bin
        for b, (label, mid) in enumerate(zip(OFFSET_BINS, OFFSET_MID_M, strict=True)):
            scans = tile_scans(tile, [3 * b + k % 3 for k in range(n)], cfg.seed + 2 + b, f"o{b}-")
            levels.append(Level("offset", "vector", label, mid, lms, scans, one))
    return levels


# -- memory -------------------------------------------------------------------------------------
def rss_mb() -> float:
    """This process's resident memory (MB, psutil) after a garbage collection and
    ``malloc_trim(0)`` (glibc returns its free heap pages to the OS), so that memory freed earlier
    and kept by the allocator does not hide or inflate what a step keeps."""
    import psutil

    gc.collect()
    try:
        import ctypes

        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass
    return psutil.Process().memory_info().rss / 2**20


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
    """Retained and peak resident memory (MB) of a block: ``with MemoryProbe() as m: ...``, then
    ``m.retained_mb`` (RSS after minus before) and ``m.peak_mb`` (the peak above the memory
    before; NaN where the OS cannot tell). Both see what tracemalloc does not (numba, open3d)."""

    def __enter__(self) -> MemoryProbe:
        self._r0 = rss_mb()
        self._peak = reset_peak()
        return self

    def __exit__(self, *exc: object) -> None:
        self.peak_mb = peak_mb() - self._r0 if self._peak else math.nan
        self.retained_mb = rss_mb() - self._r0


# -- one level ----------------------------------------------------------------------------------
def _tiled(tile: VectorMap, tiling: Tiling, kind: str, resolution_m: float) -> tuple[VectorMap | GridMap, int]:
    vm = tile_vector_map(tile, tiling)
    return (rasterize(vm, resolution_m) if kind == "grid" else vm), len(vm.segments)


def build_map(tile: VectorMap, lv: Level, resolution_m: float) -> tuple[VectorMap | GridMap, dict]:
    """The level's map (``tile`` repeated, rasterised at ``resolution_m`` metres for a grid) and
    its ``(map)`` preparation row: building it, timed by the harness's timer, and its memory."""
    with MemoryProbe() as mem:
        t = timed(_tiled, tile, lv.tiling, lv.kind, resolution_m)
        (m, segments), cpu_s, wall_s = t.estimate, t.cpu_s, t.wall_s
        del t
    cells = int(np.prod(m.shape)) if isinstance(m, GridMap) else 0
    return m, {"matcher": "(map)", "kind": lv.kind, "tiles": lv.tiling.tiles, "size": lv.size,
               "cells": cells, "segments": segments, "prep_cpu_s": cpu_s, "prep_wall_s": wall_s,
               "rss_delta_mb": mem.retained_mb, "peak_mb": mem.peak_mb, "status": "ok"}


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


def scan_row(lv: Level, scan: TileScan, name: str, matcher: Matcher, problem: Problem, position: int) -> dict:
    """One timed ``localize`` (:func:`~tfloc.harness.workspace.timed_localize`) as a row of
    ``SCAN_COLUMNS``: CPU, system and wall ms, errors (m, °), success and status. A raising
    matcher is a row (``error:…``, no times), not a crash."""
    sys0 = _system_s()
    try:
        t = timed_localize(matcher, problem)
        est, status, cpu_s, wall_s = t.estimate, str(status_of(t.estimate)), t.cpu_s, t.wall_s
    except Exception as exc:  # noqa: BLE001 - a raising matcher is a result
        est, status, cpu_s, wall_s = None, f"error:{type(exc).__name__}: {exc}"[:200], math.nan, math.nan
    sys_s = _system_s() - sys0
    d, o = est.pose.error_to(scan.truth) if est is not None else (math.nan, math.nan)
    return {"matcher": name, "axis": lv.axis, "kind": lv.kind, "level": lv.level, "size": lv.size,
            "tiles": lv.tiling.tiles, "beams": lv.laser.n_beams, "fov_deg": round(math.degrees(lv.laser.fov), 6),
            "scan_id": scan.scan_id, "offset_bin": scan.offset_bin,
            "init_dist_m": scan.initial.distance_to(scan.truth), "position": position,
            "cpu_ms": 1000.0 * cpu_s, "sys_ms": 1000.0 * sys_s, "wall_ms": 1000.0 * wall_s,
            "dist_err_m": d, "orient_err_deg": math.degrees(o),
            "success": int(status == "ok" and THRESHOLDS.success(d, o)), "status": status}


def time_level(lv: Level, tile: VectorMap, matchers: dict[str, Matcher], cfg: StudyConfig, log: Log,
               step: Callable[[int], None] = lambda n: None) -> tuple[list[dict], list[dict], dict]:
    """Prepare (timed, memory measured), warm up and time every matcher of ``matchers`` on the
    level's scans, interleaved. Returns the scan rows, the matchers' preparation rows and the
    map's own; ``step(n)`` is told of every ``n`` (scan, matcher) pairs done or given up."""
    base, map_row = build_map(tile, lv, cfg.resolution_m)
    ranges = [scan_ranges(tile, s, lv.laser) for s in lv.scans]
    shape = {"kind": lv.kind, "tiles": lv.tiling.tiles, "size": lv.size, "cells": map_row["cells"],
             "segments": map_row["segments"] if isinstance(base, VectorMap) else 0}
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
            prep.append({"matcher": name, **shape, "prep_cpu_s": math.nan, "prep_wall_s": math.nan,
                         "rss_delta_mb": math.nan, "peak_mb": math.nan, "status": f"error:{type(exc).__name__}"})
            step(len(lv.scans))
            continue
        ready.append((name, m, problems))
        prep.append({"matcher": name, **shape, "prep_cpu_s": t.cpu_s, "prep_wall_s": t.wall_s,
                     "rss_delta_mb": mem.retained_mb, "peak_mb": mem.peak_mb, "status": "ok"})
    rows = []
    for i, s in enumerate(lv.scans):
        for pos, (name, m, problems) in rotated(ready, i):
            rows.append(scan_row(lv, s, name, m, problems[i], pos))
        step(len(ready))
    return rows, prep, map_row


# -- matchers and the study's fingerprint -------------------------------------------------------
def study_matchers(names: Sequence[str] | None, log: Log) -> dict[str, Matcher]:
    """Every named matcher with its defaults, built by :func:`tfloc.core.matcher.get_matcher`
    (default: every registered single-scan local matcher); one whose library is missing is left
    out with one line to ``log``.

    By default a tracker without a single-scan mode (amcl, tf-plus-recover), ``odometry`` (no
    objective: it answers its guess at no cost) and a global matcher (tf-global, bnb-global) are
    left out, each with one line: the study's problems are local ones, and a global matcher's cost
    against the area is its own axis (``results/global``). Named, they run (a global matcher then
    answers the local problem its own way; a tracker without a single-scan mode cannot)."""
    chosen = names is not None
    out: dict[str, Matcher] = {}
    for name in names if chosen else available_matchers():
        if ":" in name:
            raise ConfigError(f"matcher {name!r}: the scaling study runs registered matchers only")
        try:
            m = get_matcher(name)
        except LibraryMissingError as exc:
            log(f"left out: {exc}")
            continue
        why = ("no single-scan mode" if not has_single_scan_mode(m) else "" if chosen
               else "a global matcher" if solves_global(m)
               else "no objective: it answers its guess" if not hasattr(m, "score") else "")
        if why:
            log(f"left out: {name} ({why})")
            continue
        out[name] = m
    if not out:
        raise ConfigError("scaling study: no matcher to run")
    return out


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def study_fingerprint(cfg: StudyConfig, matchers: Sequence[str]) -> dict[str, Any]:
    """What decides the study's rows: the tfloc version, the tile map's content hash, every
    matcher with its resolved parameters (:func:`tfloc.harness.preflight.build_matcher`), the
    success thresholds and the configuration; JSON-normalised."""
    path = Path(cfg.map_path)
    fp = {"tfloc": tfloc_code(), "datasets": {"map": {path.name: _sha256(path)}},
          "matchers": {n: {"name": n, "params": build_matcher(MatcherSpec.make(n))} for n in matchers},
          "success": THRESHOLDS.to_dict(), "study": asdict(cfg)}
    return json.loads(json.dumps(fp, default=str))


def study_differences(old: dict | None, new: dict) -> list[str]:
    """What differs between a recorded study fingerprint and a new one, one phrase each
    (:func:`tfloc.harness.fingerprint.differences`, then the configuration's fields)."""
    if not isinstance(old, dict):
        return ["it records no fingerprint (made by an older tfloc, or study.json is missing or unreadable)"]
    a = old.get("study") if isinstance(old.get("study"), dict) else {}
    return differences(old, new) + [f"{k} {json.dumps(a.get(k))} → {json.dumps(v)}"
                                    for k, v in new["study"].items() if a.get(k) != v]


# -- the output directory -----------------------------------------------------------------------
def _write_atomic(path: Path, text: str) -> None:
    """``text`` into ``path`` atomically (:func:`tfloc.io.atomic.replace_atomically`)."""
    replace_atomically(path, lambda fh: fh.write(text))


@dataclass(frozen=True)
class StudyDir:
    """A study's output directory: ``study.json`` and the raw rows (the derived files are the
    report's)."""

    path: Path

    def doc(self) -> dict | None:
        """``study.json``, or None if there is none; a malformed one is a :class:`ResultsError`."""
        f = self.path / STUDY_JSON
        if not f.exists():
            return None
        try:
            doc = json.loads(f.read_text())
        except (OSError, ValueError) as exc:
            raise ResultsError(f"{f}: cannot read ({exc})") from None
        if not isinstance(doc, dict) or not isinstance(doc.get("config", {}), dict):
            raise ResultsError(f"{f}: expected a JSON object with a config object")
        return doc

    def has_rows(self) -> bool:
        return (self.path / SCAN_CSV).exists()

    def raw(self) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
        """The rows of ``scaling.csv``, ``prep.csv`` and ``skips.csv`` (empty where missing)."""
        out = []
        for name, cols in ((SCAN_CSV, SCAN_COLUMNS), (PREP_CSV, PREP_COLUMNS), (SKIPS_CSV, SKIP_COLUMNS)):
            f = self.path / name
            try:
                df = pd.read_csv(f) if f.exists() else pd.DataFrame(columns=cols)
            except (OSError, ValueError) as exc:
                raise ResultsError(f"{f}: cannot read ({exc})") from None
            if list(df.columns) != cols:
                raise ResultsError(f"{f}: expected the columns {', '.join(cols)}")
            out.append(df)
        return out[0], out[1], out[2]

    def write_raw(self, rows: list[dict], prep: list[dict], skips: list[dict]) -> None:
        """The raw rows, each file atomically."""
        for name, data, cols in ((SCAN_CSV, rows, SCAN_COLUMNS), (PREP_CSV, prep, PREP_COLUMNS),
                                 (SKIPS_CSV, skips, SKIP_COLUMNS)):
            _write_atomic(self.path / name, pd.DataFrame(data, columns=cols).to_csv(index=False, float_format="%.6g"))

    def write_doc(self, doc: dict) -> None:
        _write_atomic(self.path / STUDY_JSON, json.dumps(doc, indent=1) + "\n")

    def discard(self, names: Sequence[str] = ()) -> None:
        """Remove ``study.json``, the raw rows and ``names`` (``--regenerate``)."""
        for name in (STUDY_JSON, SCAN_CSV, PREP_CSV, SKIPS_CSV, *names):
            (self.path / name).unlink(missing_ok=True)


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo``), else :func:`platform.processor`."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def provenance(doc: dict) -> dict:
    """What the README says of how the study was made, from ``study.json``: the command, cores,
    machine, code, the first start, load averages, and wall and CPU seconds over its sessions."""
    sessions = doc.get("sessions") or [{}]
    total = {k: round(sum(float(s.get(k) or 0.0) for s in sessions), 1) for k in ("wall_s", "cpu_s")}
    return {"command": doc.get("command"), "cores": sessions[-1].get("cores"), "cpu": doc.get("cpu"),
            "python": (doc.get("machine") or {}).get("python"), "git": doc.get("git") or {},
            "started": sessions[0].get("started"), "loadavg_start": sessions[0].get("loadavg_start"),
            "loadavg_end": sessions[-1].get("loadavg_end"), "sessions": len(sessions), **total}


# -- the study ----------------------------------------------------------------------------------
def _done_rows(levels: list[Level], done: set[str], sd: StudyDir) -> tuple[list[dict], list[dict], list[dict], list[dict]]:
    """The recorded rows of the levels done (scan, map, matcher preparation and skip rows); rows
    of a level cut off before ``study.json`` recorded it are dropped."""
    if not done:
        return [], [], [], []
    rows, prep, skips = sd.raw()
    area = {(lv.kind, lv.tiling.tiles): lv.key for lv in levels if lv.axis == "area"}

    def kept(df: pd.DataFrame) -> list[dict]:
        keys = (f"{a}/{k}/{lv}" for a, k, lv in zip(df["axis"], df["kind"], df["level"], strict=True))
        return df[[k in done for k in keys]].to_dict("records")

    prep = prep[[area.get((k, int(t))) in done for k, t in zip(prep["kind"], prep["tiles"], strict=True)]]
    maps = prep["matcher"] == "(map)"
    return kept(rows), prep[maps].to_dict("records"), prep[~maps].to_dict("records"), kept(skips)


def _open(sd: StudyDir, fp: dict, levels: list[Level], regenerate: bool) -> tuple[dict | None, set[str]]:
    """The directory's ``study.json`` and the levels it has done, after the configuration check:
    another configuration is refused (:class:`ConfigError`) unless ``regenerate``, which also
    starts a complete study over."""
    doc = sd.doc()
    if doc is None and not sd.has_rows():
        return None, set()
    diff = study_differences((doc or {}).get("fingerprint"), fp)
    if diff and not regenerate:
        more = f" (and {len(diff) - 3} more)" if len(diff) > 3 else ""
        raise ConfigError(f"{sd.path} holds a study of another configuration: {'; '.join(diff[:3])}{more}; "
                          "to start it over give --regenerate, to keep it choose another --out")
    done = set((doc or {}).get("done", [])) & {lv.key for lv in levels}
    if diff or (regenerate and len(done) == len(levels)):
        sd.discard()
        return None, set()
    return doc, done


def run_study(cfg: StudyConfig, out: Path, log: Log = print, progress: Progress | None = None,
              regenerate: bool = False, command: str = "") -> StudyDir:
    """Run (or resume) the study into ``out``: ``study.json`` and the raw rows, written after
    every level (module docstring). Returns the directory; the caller renders it. The process is
    pinned, every library on one thread, before any matcher is built."""
    clock = time.process_time(), time.perf_counter()
    with pinned() as cores:
        return _study(cfg, StudyDir(Path(out)), cores, log, progress, regenerate, command, clock)


def _study(cfg: StudyConfig, sd: StudyDir, cores: list[int], log: Log, progress: Progress | None,
           regenerate: bool, command: str, clock: tuple[float, float]) -> StudyDir:
    """:func:`run_study` once pinned: the configuration check, ``study.json``, the levels."""
    tile = read_vector_map(cfg.map_path)
    matchers = study_matchers(cfg.matchers or None, log)
    fp = study_fingerprint(cfg, list(matchers))
    levels = study_levels(cfg, tile)
    doc, done = _open(sd, fp, levels, regenerate)
    if all(lv.key in done for lv in levels):
        return sd
    try:
        sd.path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ResultsError(f"{sd.path}: cannot create the directory ({exc.strerror or exc})") from None
    state = _done_rows(levels, done, sd)
    env = environment()
    session = {"started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "loadavg_start": load_average(),
               "levels_done_before": len(done), "git": env["git"], "cores": cores}
    doc = {"config": asdict(cfg), "fingerprint": fp, "command": command, **env, "cpu": cpu_model(),
           "matchers": list(matchers), "levels": [lv.key for lv in levels],
           "sessions": list((doc or {}).get("sessions", [])) + [session],
           "done": [lv.key for lv in levels if lv.key in done]}
    sd.write_doc(doc)
    gc.freeze()  # the libraries' objects: every later gc.collect (memory probes) skips them
    try:
        _run_levels(cfg, tile, matchers, levels, done, state, sd, doc, log, progress, clock)
    finally:
        gc.unfreeze()
    return sd


def _run_levels(cfg: StudyConfig, tile: VectorMap, matchers: dict[str, Matcher], levels: list[Level],
                done: set[str], state: tuple[list[dict], ...], sd: StudyDir, doc: dict, log: Log,
                progress: Progress | None, clock: tuple[float, float]) -> None:
    """:func:`run_study`'s loop: every level not done, the budgets, rows and ``study.json``
    written after each; the session's CPU and wall seconds counted from ``clock``."""
    rows, map_prep, prep, skips = state
    session = doc["sessions"][-1]
    c0, w0 = clock
    total = sum(len(lv.scans) for lv in levels) * len(matchers)
    count = sum(len(lv.scans) for lv in levels if lv.key in done) * len(matchers)

    def step(n: int) -> None:
        nonlocal count
        count += n
        if progress is not None:
            progress(count, total)

    step(0)
    out_of_budget: dict[tuple[str, str, str], str] = {}   # (axis, kind, matcher) → why
    try:
        for lv in levels:
            if lv.key in done:   # a resumed level: its rows decide the budgets as when it ran
                r = pd.DataFrame([x for x in rows if x["axis"] == lv.axis and x["kind"] == lv.kind
                                  and x["level"] == lv.level], columns=SCAN_COLUMNS)
                p = pd.DataFrame([x for x in prep if lv.axis == "area" and x["kind"] == lv.kind
                                  and x["tiles"] == lv.tiling.tiles], columns=PREP_COLUMNS)
                _budgets(cfg, lv, r, p, out_of_budget)
                continue
            active = {n: m for n, m in matchers.items() if (lv.axis, lv.kind, n) not in out_of_budget}
            for n in (n for n in matchers if n not in active):
                skips.append({"axis": lv.axis, "kind": lv.kind, "level": lv.level, "size": lv.size, "matcher": n,
                              "why": out_of_budget[(lv.axis, lv.kind, n)]})
                if lv.axis == "area":
                    prep.append({"matcher": n, "kind": lv.kind, "tiles": lv.tiling.tiles, "size": lv.size,
                                 "cells": 0, "segments": 0, "prep_cpu_s": math.nan, "prep_wall_s": math.nan,
                                 "rss_delta_mb": math.nan, "peak_mb": math.nan, "status": "skipped"})
            step(len(lv.scans) * (len(matchers) - len(active)))
            if active:
                c1 = time.process_time()
                r, p, m = time_level(lv, tile, active, cfg, log, step)
                gc.collect()
                rows += r
                if lv.axis == "area":
                    prep += p
                    map_prep.append(m)
                med = _budgets(cfg, lv, pd.DataFrame(r, columns=SCAN_COLUMNS), pd.DataFrame(p, columns=PREP_COLUMNS),
                               out_of_budget)
                log(f"{lv.axis:6s} {lv.kind:6s} {lv.level:18s} {len(lv.scans)} scans × {len(active)} matchers: "
                    f"{time.process_time() - c1:6.1f} s CPU; median ms "
                    + ", ".join(f"{n} {v:.1f}" for n, v in med.items()))
            sd.write_raw(rows, map_prep + prep, skips)
            done.add(lv.key)
            session.update(wall_s=round(time.perf_counter() - w0, 1), cpu_s=round(time.process_time() - c0, 1))
            doc["done"] = [x.key for x in levels if x.key in done]
            sd.write_doc(doc)
    finally:
        session.update(ended=time.strftime("%Y-%m-%dT%H:%M:%S%z"), loadavg_end=load_average(),
                       wall_s=round(time.perf_counter() - w0, 1), cpu_s=round(time.process_time() - c0, 1))
        sd.write_doc(doc)


def _budgets(cfg: StudyConfig, lv: Level, rows: pd.DataFrame, prep: pd.DataFrame,
             out_of_budget: dict[tuple[str, str, str], str]) -> pd.Series:
    """Record the level's matchers over budget in ``out_of_budget``; returns their median CPU ms."""
    over = over_budget(rows, prep, lv.level, cfg.budget_ms, cfg.prep_budget_s if lv.axis == "area" else None)
    out_of_budget.update({(lv.axis, lv.kind, n): why for n, why in over.items()})
    return rows.groupby("matcher", sort=False)["cpu_ms"].median()
