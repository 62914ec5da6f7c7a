"""A side-by-side timing pass: the run's matchers re-timed on a sample of its scans, in one process.

The benchmark's own runtimes come from two workers on a machine other jobs may share; their CPU
time is robust to that, their wall time is not, and neither is measured side by side. This pass
re-times a stratified sample of a run's scans so that the matchers are compared under the same
conditions:

* **Sample**: per stratum (dataset × group, e.g. one offset cell) ``per_stratum`` scans drawn
  with a seeded generator from the scans every matcher of the run answered (a scan on which a
  matcher timed out or raised in the run is left out: it would dominate the pass's time).
* **One process pinned to the configured cores** (``os.sched_setaffinity``), every library on
  one thread (:func:`tfloc.harness.threads.limit_threads`).
* **Warm-up**: for each dataset and matcher, :func:`tfloc.harness.workspace.warm` and ``warmup``
  untimed ``localize`` calls on sampled scans (kernels, map-only structures, the allocator).
* **Interleaved**: scan by scan, every matcher once, the order rotated by one per scan, so slow
  drifts of the machine (load, frequency) hit every matcher alike.
* Each call is timed by CPU time (``time.process_time``) and wall time (``time.perf_counter``).

:func:`run_timing` returns one row per (scan, matcher) (``TIMING_COLUMNS``); ``tfloc timing``
writes them to ``RUN/timing.csv`` and the summary (:mod:`tfloc.evaluation.timing`) to
``RUN/timing.md``.

The pinning (:func:`pinned`) and the interleaving (:func:`rotated`) are also the scaling study's
(:mod:`tfloc.harness.scaling`).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TypeVar

import numpy as np
import pandas as pd

from tfloc.errors import ConfigError
from tfloc.io.rundir import RunDir, RunInfo

from .identity import git_state
from .runner import load_average
from .threads import limit_threads
from .workspace import load_dataset, load_matcher, problem_of, timed_localize, warm

TIMING_COLUMNS = ["dataset", "scan_id", "group", "matcher", "position", "cpu_ms", "wall_ms"]
SEED = 20261130
T = TypeVar("T")


def read_run(run_dir: Path) -> tuple[pd.DataFrame, RunInfo]:
    """The rows and ``run.json`` of a run (:class:`~tfloc.io.rundir.RunDir`; both required)."""
    rd = RunDir(run_dir)
    info = rd.info(required=True)
    return rd.results(), info


def sample_scans(df: pd.DataFrame, per_stratum: int, seed: int = SEED) -> pd.DataFrame:
    """``per_stratum`` scans per (dataset, group) that every matcher answered, seeded; columns
    dataset, scan_id, group, in dataset order, then group, then scan id."""
    if per_stratum < 1:
        raise ConfigError(f"per-stratum sample size must be ≥ 1, got {per_stratum}")
    answered = df["status"].fillna("").isin(["ok", "failed"])
    n_matchers = df["matcher"].nunique()
    ok = df[answered].groupby(["dataset", "scan_id"])["matcher"].nunique() == n_matchers
    good = set(ok[ok].index)
    scans = df[["dataset", "scan_id", "group"]].drop_duplicates(["dataset", "scan_id"])
    scans = scans[[k in good for k in zip(scans["dataset"], scans["scan_id"], strict=True)]]
    rng = np.random.default_rng(seed)
    parts = []
    order = {d: i for i, d in enumerate(dict.fromkeys(df["dataset"]))}
    for _, g in sorted(scans.groupby(["dataset", "group"], sort=True), key=lambda kv: (order[kv[0][0]], kv[0][1])):
        g = g.sort_values("scan_id")
        parts.append(g.iloc[np.sort(rng.choice(len(g), size=min(per_stratum, len(g)), replace=False))])
    cols = ["dataset", "scan_id", "group"]
    return pd.concat(parts, ignore_index=True)[cols] if parts else pd.DataFrame(columns=cols)


def pin(cores: Sequence[int]) -> list[int]:
    """Pin this process to ``cores`` (where the OS allows); returns the cores it now runs on."""
    if hasattr(os, "sched_setaffinity"):
        try:
            os.sched_setaffinity(0, set(cores))
        except OSError as exc:
            raise ConfigError(f"cannot pin to cores {list(cores)}: {exc}") from None
        return sorted(os.sched_getaffinity(0))
    return []


@contextmanager
def pinned(cores: Sequence[int] | None = None) -> Iterator[list[int]]:
    """The block runs pinned to ``cores`` (default: the last core this process may run on), every
    library on one thread; yields the cores it runs on, and restores the affinity after."""
    before = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    try:
        now = pin(before[-1:] if cores is None else cores)
        limit_threads(1)
        yield now
    finally:
        if before:
            os.sched_setaffinity(0, before)


def rotated(items: Sequence[T], i: int) -> list[tuple[int, T]]:
    """Scan ``i``'s order of ``items`` (matchers): rotated by ``i``, each with its position, so
    that slow drifts of the machine hit every matcher alike."""
    k = len(items)
    return [(pos, items[(i + pos) % k]) for pos in range(k)]


def run_timing(run_dir: Path, per_stratum: int = 4, seed: int = SEED, cores: Sequence[int] | None = None,
               warmup: int = 2, progress: Callable[[int, int], None] | None = None,
               run: tuple[pd.DataFrame, RunInfo] | None = None) -> tuple[pd.DataFrame, dict]:
    """Re-time a stratified sample of the run in ``run_dir`` (see the module docstring), pinned
    to ``cores`` (default: the last core this process may run on).

    Returns the rows (``TIMING_COLUMNS``; times in ms) and a provenance dict (cores, load
    averages, sample size, seed). ``run``: the run's rows and ``run.json`` if the caller has
    already read them (:func:`read_run`)."""
    df, info_run = read_run(run_dir) if run is None else run
    specs = [m for m in info_run.matchers if m["label"] in set(df["matcher"])]
    paths = info_run.datasets
    sample = sample_scans(df, per_stratum, seed)
    if sample.empty:
        raise ConfigError(f"{run_dir}: no scan that every matcher answered")
    started, load_start = time.strftime("%Y-%m-%dT%H:%M:%S%z"), load_average()
    with pinned(cores) as on:
        rows = _time_sample(sample, specs, paths, warmup, progress)
    info = {"cores": on, "per_stratum": per_stratum, "seed": seed, "warmup": warmup,
            "scans": len(sample), "strata": int(sample.groupby(["dataset", "group"]).ngroups),
            "loadavg_start": load_start, "loadavg_end": load_average(), "started": started,
            "git": git_state(), "run_git": info_run.doc.get("git", {})}
    return rows, info


def _time_sample(sample: pd.DataFrame, specs: list[dict], paths: dict[str, Path], warmup: int,
                 progress: Callable[[int, int], None] | None) -> pd.DataFrame:
    """Warm up, then time every matcher on every sampled scan, interleaved (module docstring)."""
    matchers = [(m["label"], load_matcher(m["name"], json.dumps(m.get("params", {}), sort_keys=True)))
                for m in specs]
    problems = {}
    for d, g in sample.groupby("dataset", sort=False):
        if d not in paths:
            raise ConfigError(f"dataset {d!r} has no directory in run.json")
        scenario, scans = load_dataset(str(paths[d]))
        problems[d] = (scenario, scans)
        first = [scans[s] for s in g["scan_id"].iloc[:max(1, warmup)]]
        for _, m in matchers:  # untimed: kernels, map-only structures, allocator
            warm(m, problem_of(scenario, first[0]))
            for scan in first[:warmup]:
                m.localize(problem_of(scenario, scan))
    rows = []
    for i, r in enumerate(sample.itertuples(index=False)):
        scenario, scans = problems[r.dataset]
        scan = scans[r.scan_id]
        for pos, (label, m) in rotated(matchers, i):
            t = timed_localize(m, problem_of(scenario, scan))
            rows.append({"dataset": r.dataset, "scan_id": r.scan_id, "group": r.group, "matcher": label,
                         "position": pos, "cpu_ms": 1000.0 * t.cpu_s, "wall_ms": 1000.0 * t.wall_s})
        if progress:
            progress(i + 1, len(sample))
    return pd.DataFrame(rows, columns=TIMING_COLUMNS)
