"""Run matchers over scenario datasets: a process pool, per-task time limits, results streamed
to ``estimates.csv`` as tasks finish, and resume by skipping what is already there.

The pool is :class:`pebble.ProcessPool` (spawned workers; a task past its time limit is killed
with its worker, which is replaced). Each worker is started with every thread pool (OpenMP,
BLAS, numba, OpenCV, open3d; :mod:`tfloc.harness.threads`) limited to one thread, so that a
task's CPU time is one matcher on one core and ``jobs`` workers use ``jobs`` cores. ``run.json``
records the load average when a session starts and ends (contention shows in wall time).

Before anything is written, every matcher is built once in this process and every dataset read
once (:mod:`tfloc.harness.preflight`), and the run's fingerprint is computed
(:mod:`tfloc.harness.fingerprint`); an existing run directory is resumed only when its
fingerprint is the same.
"""

from __future__ import annotations

import multiprocessing
import os
import platform
import sys
from collections.abc import Callable
from concurrent.futures import TimeoutError as FutureTimeout
from concurrent.futures import as_completed
from importlib import metadata
from pathlib import Path

from pebble import ProcessExpired, ProcessPool
from tqdm import tqdm

from tfloc.core.result import ResultRow, Status, StatusKind
from tfloc.core.tracker import has_single_scan_mode
from tfloc.errors import ConfigError, ResultsError
from tfloc.io.estimates import ResultWriter, done_keys, drop_rows
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import (
    SEQUENCE,
    Scenario,
    check_usable,
    iter_scans,
    map_for,
    read_scans,
    read_scenario,
)

from .config import RunConfig
from .fingerprint import Staleness, stale
from .identity import git_state, recorded_packages
from .preflight import Preflight, preflight
from .task import Task, error_status, failure_row, run_task, warm_up
from .threads import limit_threads
from .workspace import load_matcher

WORKER_DIED = "worker died"  # an error row's message when the task's process died


def make_tasks(config: RunConfig, log: Callable[[str], None] | None = None,
               scenarios: dict[Path, Scenario] | None = None) -> list[Task]:
    """Every task of a run, in dataset/scan order (validates datasets): one per (scan, matcher),
    and one per (sequence, matcher) on a sequence dataset. A tracker (no single-scan mode, e.g.
    ``amcl``) is left out of the other datasets with one line to ``log``. ``scenarios``: the
    datasets as the preflight read them (read here otherwise)."""
    tasks = []
    for d in config.datasets:
        scenario = (scenarios or {}).get(Path(d)) or read_scenario(d)
        if scenario.mode == SEQUENCE:
            scans = read_scans(scenario)
            check_usable(scenario, scans, map_for(scenario, scans[0]))
            tasks += [Task(str(d), scenario.name, scans[-1].scan_id, m.label, m.name, m.params_json,
                           config.success, sequence=True, timeout_s=config.sequence_timeout_s)
                      for m in config.matchers]
            continue
        single = [m for m in config.matchers if not tracker_only(m)]
        if log is not None and len(single) < len(config.matchers):
            log(f"dataset {scenario.name}: " + ", ".join(m.label for m in config.matchers if m not in single)
                + " left out: a tracker has no single-scan mode (it runs on sequence datasets only)")
        per_group: dict[str, int] = {}
        skip = config.skip(d)
        for scan in iter_scans(scenario):
            n = per_group[scan.group] = per_group.get(scan.group, 0) + 1
            if n <= skip or (config.limit_per_group and n - skip > config.limit_per_group):
                continue
            for m in single:
                tasks.append(Task(str(d), scenario.name, scan.scan_id, m.label, m.name, m.params_json,
                                  config.success))
    return tasks


def tracker_only(spec) -> bool:
    """Whether the matcher of ``spec`` is a tracker with no single-scan mode (``start``/``step``,
    no ``localize``)."""
    try:
        m = load_matcher(spec.name, spec.params_json)
    except Exception:  # noqa: BLE001 - build_matchers reports it
        return False
    return not has_single_scan_mode(m)


def _init_worker() -> None:
    limit_threads(1)


def load_average() -> list[float] | None:
    """The 1, 5 and 15 minute load averages (``os.getloadavg``), or None where unavailable."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo``), else :func:`platform.processor`."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def environment() -> dict:
    """Package versions, git commit and machine (with the CPU's model), for ``run.json``."""
    versions = {}
    for pkg in recorded_packages():
        try:
            versions[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            versions[pkg] = None
    return {"versions": versions, "git": git_state(),
            "machine": {"platform": platform.platform(), "processor": platform.processor(),
                        "cpu": cpu_model(), "cpu_count": os.cpu_count(), "python": sys.version.split()[0],
                        "node": platform.node()}}


def session_doc(pre: Preflight) -> dict:
    """What ``run.json`` records of a session besides the sessions themselves: the configuration,
    the environment, the datasets (name → directory), what each declares and the fingerprint."""
    config = pre.config
    scenarios = [pre.scenarios[Path(d)] for d in config.datasets]
    return {"config": config.to_dict(), **environment(),
            "datasets": {sc.name: str(d) for sc, d in zip(scenarios, config.datasets, strict=True)},
            "declared": {sc.name: {"mode": sc.mode, "paper_scenarios": list(sc.paper_scenarios)}
                         for sc in scenarios},
            "fingerprint": pre.fingerprint}


#: the time limit of one warm-up (seconds): kernels compiled and cached, map-only data built
WARM_UP_S = 600.0


def execute_local(tasks: list[Task], jobs: int, timeout_s: float,
                  on_row: Callable[[ResultRow | list[ResultRow]], None]) -> None:
    """Run ``tasks`` on a local process pool; every task ends in exactly one ``on_row`` call (a
    sequence task's with its list of rows)."""
    ctx = multiprocessing.get_context("spawn")
    with ProcessPool(max_workers=jobs, context=ctx, initializer=_init_worker) as pool:
        try:
            warm = {}
            for t in tasks:  # compile kernels and load data outside the timed, time-limited tasks
                if not t.sequence:  # (a sequence task warms itself up, untimed)
                    warm.setdefault((t.dataset, t.matcher, t.params_json), t)
            # a warm-up compiles numba kernels (seconds to a minute on a loaded machine): limited
            # by WARM_UP_S, not the task limit, so a cold cache never turns tasks into timeouts
            for f in [pool.schedule(warm_up, args=(t,), timeout=max(WARM_UP_S, timeout_s)) for t in warm.values()]:
                try:
                    f.result()
                except Exception:  # noqa: BLE001 - the task itself will report the failure
                    pass
            futures = {pool.schedule(run_task, args=(t,), timeout=t.timeout_s or timeout_s): t for t in tasks}
            for fut in as_completed(futures):
                on_row(collect(fut, futures[fut]))
        except BaseException:  # a failed write, Ctrl-C: stop the workers, do not run the rest
            pool.stop()
            raise


def collect(fut, task: Task) -> ResultRow | list[ResultRow]:
    """The row(s) of a pebble future of ``run_task(task)``: its result, or a timeout/error row."""
    try:
        return fut.result()
    except (TimeoutError, FutureTimeout):
        return failure_row(task, Status(StatusKind.TIMEOUT))
    except ProcessExpired as exc:
        return failure_row(task, worker_died(exc))
    except Exception as exc:  # noqa: BLE001
        return failure_row(task, error_status(exc))


def worker_died(exc: BaseException) -> Status:
    """The status of a task whose worker process died under it."""
    return Status.of(StatusKind.ERROR, f"{WORKER_DIED} ({exc})")


Executor = Callable[[list[Task], int, float, Callable[[ResultRow | list[ResultRow]], None]], None]


def _sequence_pairs(tasks: list[Task]) -> set[tuple[str, str]]:
    return {(t.dataset_name, t.label) for t in tasks if t.sequence}


def _drop_cut_sequences(rd: RunDir, tasks: list[Task], done: set) -> set:
    """A sequence task writes its rows one by one and its last row last: rows of a sequence
    whose last row is missing were cut off by a kill. They are dropped (the file is rewritten
    atomically) and the sequence runs again; returns the keys that remain."""
    finished = {(t.dataset_name, t.label) for t in tasks if t.sequence and t.key in done}
    cut = {k for k in done if (k[0], k[2]) in _sequence_pairs(tasks) - finished}
    if cut:
        drop_rows(rd.estimates, done - cut)
    return done - cut


def _what(st: Staleness, done: set) -> str:
    """What ``--regenerate`` re-runs of a run whose rows ``done`` are made stale by ``st``."""
    if st.everything or not any(st.keeps(k) for k in done):
        return "every task (no row of the run stays current)"
    parts = []
    if st.matchers:
        parts.append(f"the tasks of {', '.join(sorted(st.matchers))}")
    if st.datasets:
        parts.append(f"dataset{'s' if len(st.datasets) > 1 else ''} {', '.join(sorted(st.datasets))}")
    return (" and ".join(parts) or "the new matchers' tasks") + " (the other rows are kept)"


def run(config: RunConfig, progress: bool | None = None, executor: Executor = execute_local,
        regenerate: bool = False, retry_errors: bool = False) -> Path:
    """Run (or resume) a benchmark; returns the run directory holding ``estimates.csv``.

    Every matcher is built first, in this process (a bad parameter raises :class:`ConfigError`
    before anything is written). An existing ``estimates.csv`` is resumed when the run's
    fingerprint is the same: finished tasks are skipped; another configuration raises
    :class:`ConfigError` in one line saying what differs (which matchers' code changed, and
    which files). With ``regenerate``, a *complete* previous run or
    one of another configuration is discarded and run again (an interrupted one is still
    resumed), so one command both reproduces a committed reference run and survives
    interruptions. Where only some rows are stale (:func:`tfloc.harness.fingerprint.stale`: a
    matcher's code or parameters changed, a dataset's files), ``regenerate`` drops those rows
    and runs their tasks again, keeping the rest. With ``retry_errors``, rows whose status is ``error:…`` or ``timeout`` are
    removed (the file is rewritten atomically) and their tasks run again.
    """
    log = lambda line: print(line, file=sys.stderr)  # noqa: E731
    pre = preflight(config, log=log)
    config = pre.config
    rd = RunDir(Path(config.out))
    fp = pre.fingerprint
    tasks = make_tasks(config, log, pre.scenarios)
    try:
        done = done_keys(rd.estimates) if rd.path.is_dir() else set()
    except ResultsError:  # damaged, or written by another version: only --regenerate goes on
        if not regenerate:
            raise
        rd.discard()
        done = set()
    partial = False
    if done:
        st = stale(rd.recorded_fingerprint(), fp)
        if st and not regenerate:
            raise ConfigError(f"{rd.path} holds a run of another configuration: {'; '.join(st.reasons[:3])}"
                              + (f" (and {len(st.reasons) - 3} more)" if len(st.reasons) > 3 else "")
                              + f"; give --regenerate to re-run {_what(st, done)}, or choose another --out")
        if st:
            keep = {k for k in done if st.keeps(k)}
            if keep:
                drop_rows(rd.estimates, keep)
                rd.discard_products()
                log(f"{rd.path}: re-running {_what(st, done)}: {'; '.join(st.reasons[:3])}")
                partial = True
            else:
                rd.discard()
            done = keep
    elif rd.run_json.is_file() and stale(rd.recorded_fingerprint(), fp):
        rd.discard()  # no rows, but the record of another configuration: its sessions are not this run's
    done = _drop_cut_sequences(rd, tasks, done)
    todo = [t for t in tasks if t.key not in done]
    if regenerate and not todo and tasks and not partial:
        rd.discard()
        todo = tasks
    elif retry_errors and done:
        bad = done - done_keys(rd.estimates, redo=("error", "timeout"))
        pairs = {(k[0], k[2]) for k in bad}
        retry = {t.key for t in tasks if t.key in done and (t.key in bad or t.sequence and t.key[::2] in pairs)}
        drop = {k for k in done if k in retry or (k[0], k[2]) in pairs & _sequence_pairs(tasks)}
        drop_rows(rd.estimates, done - drop)
        todo = [t for t in tasks if t.key not in done or t.key in retry]
    rd.make()
    rd.start_session(session_doc(pre), len(tasks), len(tasks) - len(todo), load_average())
    if not todo:
        log(f"{rd.path}: already complete: 0 tasks run (--regenerate runs it again)")
        return rd.path
    if done:
        log(f"{rd.path}: resuming: {len(tasks) - len(todo)} of {len(tasks)} tasks done by the same code "
            "and configuration")
    bar = tqdm(total=len(tasks), initial=len(tasks) - len(todo), unit="task", desc=config.name,
               disable=None if progress is None else not progress, smoothing=0.05, mininterval=1.0)
    failures = 0
    with ResultWriter(rd.estimates) as writer:
        def on_row(rows: ResultRow | list[ResultRow]) -> None:
            nonlocal failures
            for row in rows if isinstance(rows, list) else [rows]:  # a sequence's last row last
                writer.write(row)
                failures += row.status.kind in (StatusKind.ERROR, StatusKind.TIMEOUT)
            bar.update(1)
            if failures:
                bar.set_postfix(errors=failures, refresh=False)

        try:
            executor(todo, config.jobs, config.timeout_s, on_row)
        finally:
            bar.close()
            rd.close_session(load_average())
    return rd.path
