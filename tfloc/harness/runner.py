"""Run matchers over scenario datasets: a pebble process pool, per-task time limits, resume.

A task is one (dataset, scan, matcher). Workers are spawned processes; each loads the
datasets, their maps and the matchers once (pool initializer), so tasks carry only ids.
Thread pools are limited through OMP/OPENBLAS/MKL/NUMBA_NUM_THREADS set before the pool
starts: ``max(1, 2 // jobs)`` threads per worker, so a matcher gets at most 2 cores.
Each finished row is appended to ``estimates.csv`` at once (flush + fsync); a re-run skips
the (dataset, scan_id, matcher) keys already there, so a killed run resumes without repeats.
"""

from __future__ import annotations

import csv
import math
import multiprocessing
import os
import sys
import time
from concurrent.futures import FIRST_COMPLETED, wait
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ConfigError, MatcherError
from .config import RunConfig
from .dataset import iter_scans, map_for, read_scenario
from .metrics import classify, pose_errors

COLUMNS = ["dataset", "scan_id", "group", "matcher", "true_x", "true_y", "true_theta",
           "init_x", "init_y", "init_theta", "est_x", "est_y", "est_theta", "dist_err_m",
           "orient_err_rad", "init_dist_err_m", "init_orient_err_rad", "runtime_s", "converged",
           "iterations", "evaluations", "score_est", "score_true", "status", "outcome"]
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


def make_matcher(spec: str, params: dict):
    """A registered matcher name, or ``module:Class`` (e.g. a test's toy matcher)."""
    if ":" in spec:
        import importlib

        mod, _, attr = spec.partition(":")
        try:
            return getattr(importlib.import_module(mod), attr)(**params)
        except (ImportError, AttributeError) as exc:
            raise MatcherError(f"cannot load matcher {spec!r}: {exc}") from None
    from ..matcher import get_matcher

    return get_matcher(spec, **params)


# ---------------------------------------------------------------- worker side
_W: dict = {}


def _init_worker(datasets: list[str], matchers: list[tuple[str, str, dict]]) -> None:
    """Pool initializer: load every dataset (scans by id, maps) and build every matcher once."""
    _W["data"] = {}
    for d in datasets:
        sc = read_scenario(d)
        _W["data"][sc.name] = (sc, {s.scan_id: s for s in iter_scans(sc)}, {})
    _W["matchers"] = {}
    for label, spec, params in matchers:
        try:
            _W["matchers"][label] = make_matcher(spec, params)
        except Exception as exc:  # reported on each of its rows
            _W["matchers"][label] = exc


def _one_line(exc: BaseException) -> str:
    msg = " ".join(f"{type(exc).__name__}: {exc}".split())
    return msg[:200]


def run_task(dataset: str, scan_id: str, label: str) -> dict:
    """Localize one scan with one matcher (in a worker); never raises."""
    from ..problem import Problem

    sc, scans, cache = _W["data"][dataset]
    scan = scans[scan_id]
    row = base_row(dataset, scan, label)
    m = _W["matchers"][label]
    if isinstance(m, Exception):
        row["status"] = f"error:{_one_line(m)}"
        return row
    try:
        problem = Problem(map_for(sc, scan, cache), sc.laser, scan.ranges, scan.initial,
                          where=f"{sc.scans_path}:{scan.line}")
        t0 = time.perf_counter()
        est = m.localize(problem)
        row["runtime_s"] = time.perf_counter() - t0
    except Exception as exc:
        row["status"] = f"error:{_one_line(exc)}"
        return row
    p = getattr(est, "pose", None)
    if p is None:
        row["status"] = "failed"
        return row
    row.update(est_x=p.x, est_y=p.y, est_theta=p.theta, converged=bool(est.converged),
               iterations=int(est.iterations), evaluations=int(est.evaluations))
    row["status"] = "ok" if p.is_finite() else "failed"
    if scan.true is not None and p.is_finite():
        for col, pose in (("score_est", p), ("score_true", scan.true)):
            try:
                row[col] = float(m.score(problem, pose))
            except Exception:
                row[col] = math.nan
    return row


def base_row(dataset: str, scan, label: str) -> dict:
    """A row with the scan's poses filled in and no estimate."""
    row = dict.fromkeys(COLUMNS, math.nan)
    t = scan.true
    row.update(dataset=dataset, scan_id=scan.scan_id, group=scan.group, matcher=label,
               init_x=scan.initial.x, init_y=scan.initial.y, init_theta=scan.initial.theta,
               converged="", iterations="", evaluations="", status="", outcome="")
    if t is not None:
        row.update(true_x=t.x, true_y=t.y, true_theta=t.theta)
    return row


# ---------------------------------------------------------------- main side
@dataclass(frozen=True)
class Task:
    dataset: str
    scan_id: str
    matcher: str


def finish_row(row: dict, cfg: RunConfig) -> dict:
    """Fill in errors and outcome (pure)."""
    true = np.array([[row[k] for k in ("true_x", "true_y", "true_theta")]], float)
    est = np.array([[row[k] for k in ("est_x", "est_y", "est_theta")]], float)
    ini = np.array([[row[k] for k in ("init_x", "init_y", "init_theta")]], float)
    (d,), (a,) = pose_errors(true, est)
    (di,), (ai,) = pose_errors(true, ini)
    row.update(dist_err_m=d, orient_err_rad=a, init_dist_err_m=di, init_orient_err_rad=ai)
    if np.isfinite(true).all():
        row["outcome"] = classify(pd.DataFrame([row]), cfg.success_dist_m, cfg.success_orient_rad).iloc[0]
    return row


def _fmt(v) -> str:
    if isinstance(v, float | np.floating):
        return "" if math.isnan(v) else repr(float(v))
    return str(v)


def read_done(path: Path) -> set[tuple[str, str, str]]:
    """Keys already in ``estimates.csv``; a torn last line (killed mid-write) is cut off."""
    if not path.exists() or path.stat().st_size == 0:
        return set()
    data = path.read_bytes()
    if not data.endswith(b"\n"):
        cut = data.rfind(b"\n") + 1
        with path.open("r+b") as fh:
            fh.truncate(cut)
        data = data[:cut]
    lines = data.decode().splitlines()
    if not lines:
        return set()
    if lines[0].split(",") != COLUMNS:
        raise ConfigError(f"{path}: header differs from this version's columns; use another --out")
    return {(r["dataset"], r["scan_id"], r["matcher"]) for r in csv.DictReader(lines)}


def plan(cfg: RunConfig) -> tuple[list[Task], list[str]]:
    """All tasks of a run and the dataset directories (validated before any work starts)."""
    tasks, names, dirs = [], {}, []
    labels = [lab for lab, _ in cfg.matcher_specs()]
    for d in cfg.datasets:
        sc = read_scenario(d)
        if sc.name in names:
            raise ConfigError(f"datasets {names[sc.name]} and {d} share the name {sc.name!r}")
        names[sc.name] = d
        dirs.append(str(Path(d).resolve()))
        for scan in iter_scans(sc):
            tasks += [Task(sc.name, scan.scan_id, lab) for lab in labels]
    return tasks, dirs


def run(cfg: RunConfig, progress: bool | None = None, log=print) -> Path:
    """Run (or resume) ``cfg``; returns the estimates.csv path."""
    from .runinfo import write_run_json

    out = Path(cfg.out)
    out.mkdir(parents=True, exist_ok=True)
    tasks, dirs = plan(cfg)
    path = out / "estimates.csv"
    done = read_done(path)
    todo = [t for t in tasks if (t.dataset, t.scan_id, t.matcher) not in done]
    write_run_json(out / "run.json", cfg, n_tasks=len(tasks), n_done_before=len(tasks) - len(todo))
    log(f"{out}: {len(tasks)} tasks, {len(tasks) - len(todo)} already done, {len(todo)} to run "
        f"with {cfg.jobs} worker(s), {max(1, 2 // cfg.jobs)} thread(s) each")
    if not todo:
        return path
    threads = str(max(1, 2 // cfg.jobs))
    for v in THREAD_VARS:
        os.environ[v] = threads
    from pebble import ProcessPool
    from tqdm import tqdm

    specs = [(lab, spec, dict(cfg.params.get(lab, {}))) for lab, spec in cfg.matcher_specs()]
    new = not path.exists() or path.stat().st_size == 0
    fh = path.open("a", newline="")
    writer = csv.writer(fh)
    if new:
        writer.writerow(COLUMNS)
    bar = tqdm(total=len(tasks), initial=len(tasks) - len(todo), unit="scan", dynamic_ncols=True,
               disable=(not sys.stderr.isatty()) if progress is None else not progress)
    pool = ProcessPool(max_workers=cfg.jobs, initializer=_init_worker, initargs=(dirs, specs),
                       context=multiprocessing.get_context("spawn"))
    try:
        futures = {pool.schedule(run_task, args=(t.dataset, t.scan_id, t.matcher),
                                 timeout=cfg.timeout_s): t for t in todo}
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                t = futures.pop(fut)
                try:
                    row = fut.result()
                except FutureTimeout:
                    row = _failed_row(t, dirs, "timeout", cfg.timeout_s)
                except Exception as exc:  # the worker died (ProcessExpired) or similar
                    row = _failed_row(t, dirs, f"error:{_one_line(exc)}")
                row = finish_row(row, cfg)
                writer.writerow([_fmt(row[c]) for c in COLUMNS])
                fh.flush()
                os.fsync(fh.fileno())
                bar.update(1)
    except BaseException:
        pool.stop()
        raise
    finally:
        pool.close()
        pool.join()
        bar.close()
        fh.close()
    write_run_json(out / "run.json", cfg, n_tasks=len(tasks), n_done_before=len(tasks) - len(todo),
                   finished=True)
    return path


_SCAN_CACHE: dict = {}


def _failed_row(t: Task, dirs: list[str], status: str, runtime: float = math.nan) -> dict:
    """A row for a task whose worker never returned (timeout, crash), read in the main process."""
    key = tuple(dirs)
    if key not in _SCAN_CACHE:
        _SCAN_CACHE.clear()
        _SCAN_CACHE[key] = {}
        for d in dirs:
            sc = read_scenario(d)
            _SCAN_CACHE[key][sc.name] = {s.scan_id: s for s in iter_scans(sc)}
    row = base_row(t.dataset, _SCAN_CACHE[key][t.dataset][t.scan_id], t.matcher)
    row.update(status=status, runtime_s=runtime)
    return row
