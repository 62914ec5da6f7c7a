"""The worker side of :mod:`tfloc.harness.dask_executor` (imported on Dask workers only).

Dask cannot kill one running task, so each Dask worker keeps a small :class:`pebble.ProcessPool`
(one spawned process per worker thread) and runs :func:`~tfloc.harness.task.run_task` there with
the task's time limit, exactly as the local runner does: a task past its limit is killed with its
process, which pebble replaces, and becomes a ``timeout`` row. The pool's processes keep the
per-process caches of :mod:`tfloc.harness.workspace`, so a dataset's scans and map are loaded once per
process, never shipped with a task. The pool lives in a :class:`distributed.WorkerPlugin`, created
when the plugin is registered and shut down with the worker.
"""

from __future__ import annotations

import multiprocessing
import os
import threading
from pathlib import Path

from distributed import WorkerPlugin, get_worker
from pebble import ProcessPool

from tfloc.core.result import ResultRow, StatusKind

from .runner import WARM_UP_S, WORKER_DIED, _init_worker, collect
from .task import Task, run_task, warm_up

PLUGIN_NAME = "tfloc-task-pool"


class TaskPool(WorkerPlugin):
    """A per-worker process pool that runs tasks with a time limit and keeps data caches warm."""

    def __init__(self) -> None:
        """Sent to the workers by pickle: no pool, no lock yet."""
        self.pool: ProcessPool | None = None

    def setup(self, worker) -> None:  # noqa: ANN001 - distributed.Worker
        n = max(1, int(worker.state.nthreads))
        self.warm: set[tuple[str, str, str]] = set()
        self.lock = threading.Lock()
        if multiprocessing.current_process().daemon:
            self.pool = None  # a daemonic process cannot have children: see preflight()
            return
        self.pool = ProcessPool(max_workers=n, context=multiprocessing.get_context("spawn"),
                                initializer=_init_worker)

    def teardown(self, worker) -> None:  # noqa: ANN001
        if self.pool is not None:
            self.pool.stop()
            self.pool.join(timeout=10)
            self.pool = None

    def run(self, task: Task, timeout_s: float) -> ResultRow | list[ResultRow]:
        """Warm up (untimed, once per dataset and matcher), then run ``task`` within its own time
        limit, else ``timeout_s``."""
        timeout_s = task.timeout_s or timeout_s
        if self.pool is None:
            raise RuntimeError("this Dask worker is a daemonic process and cannot start tfloc's "
                               "task processes; start it with DASK_DISTRIBUTED__WORKER__DAEMON=False")
        key = (task.dataset, task.matcher, task.params_json)
        with self.lock:
            cold = key not in self.warm
            self.warm.add(key)
        if cold and not task.sequence:  # load data, compile kernels outside the timed, time-limited task
            try:
                self.pool.schedule(warm_up, args=(task,), timeout=max(WARM_UP_S, timeout_s)).result()
            except Exception:  # noqa: BLE001 - the task itself will report the failure
                pass
        row = collect(self.pool.schedule(run_task, args=(task,), timeout=timeout_s), task)
        last = row[-1] if isinstance(row, list) else row
        if last.status.kind is StatusKind.TIMEOUT or last.status.message.startswith(WORKER_DIED):
            with self.lock:  # its process was replaced: the next tasks warm up again
                self.warm.clear()
        return row


def run_on_worker(task: Task, timeout_s: float) -> ResultRow | list[ResultRow]:
    """The Dask task: one (scan, matcher) pair or one (sequence, matcher), run in this worker's
    :class:`TaskPool`."""
    return get_worker().plugins[PLUGIN_NAME].run(task, timeout_s)


def preflight(datasets: list[str]) -> list[str]:
    """Problems that would make every task on this worker fail (run on each worker)."""
    problems = []
    if multiprocessing.current_process().daemon:
        problems.append("is a daemonic process and cannot start tfloc's task processes "
                        "(start it with DASK_DISTRIBUTED__WORKER__DAEMON=False)")
    missing = [d for d in datasets if not (Path(d) / "scenario.json").is_file()]
    if missing:
        problems.append(f"has no dataset {', '.join(missing)} (relative to its working directory "
                        f"{os.getcwd()}: workers need the data at the same paths as the client)")
    return problems

