"""One (scan, matcher) task, executed in a worker process: localize, time, and record what only
the worker can know.

Tasks carry only small data (dataset path, scan id, matcher spec, thresholds); the worker's
:mod:`~tfloc.harness.workspace` loads a dataset's scans and map and the matcher once per process.
Before a process times its first task of a dataset and matcher it warms up, untimed
(:func:`~tfloc.harness.workspace.warm`). A scan-to-scan dataset's map is the reference scan, new
for every scan, so its build stays in every task's time.

A row records the estimate, its errors against the truth, the CPU and wall time of ``localize``
and, for a failure under the run's thresholds, the matcher's own objective at its answer and at
the truth (``score_est``, ``score_true``: only the worker holds the matcher and the problem). Its
``outcome`` is :func:`tfloc.evaluation.outcome.outcome`, the one rule (the report applies the same
function to the same columns). A global problem given to a local matcher is an ``invalid:`` row
(:func:`tfloc.core.matcher.check_solvable`); a global matcher's first five hypotheses go into
``info["hypotheses"]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tfloc.core.matcher import check_solvable
from tfloc.core.result import ResultRow, Status, StatusKind
from tfloc.core.thresholds import Thresholds
from tfloc.errors import InvalidProblemError
from tfloc.evaluation.outcome import AMBIGUOUS, NO_ANSWER, outcome
from tfloc.evaluation.relocalization import HYPOTHESES_KEY, hypotheses_info
from tfloc.io.estimates import result_row
from tfloc.io.scenario import Scan, load_dataset

from .workspace import load_matcher, problem_of, status_of, timed_localize, warm


@dataclass(frozen=True)
class Task:
    """What a worker needs to run one matcher on one scan."""

    dataset: str          # dataset directory
    dataset_name: str
    scan_id: str
    label: str            # matcher label in the results
    matcher: str          # registered matcher name (or "module:Class")
    params_json: str = "{}"
    thresholds: Thresholds = Thresholds()
    sequence: bool = False  # a whole sequence (scan_id: its last scan), tracked: harness/track.py
    timeout_s: float = 0.0  # this task's time limit (0: the run's per-task limit)

    @property
    def key(self) -> tuple[str, str, str]:
        """The key of the task's (last) row: a sequence task is done when its last row is written."""
        return (self.dataset_name, self.scan_id, self.label)


def base_row(task: Task, scan: Scan | None) -> ResultRow:
    """The row of a task before its matcher answers: identity, truth and initial guess
    (:func:`tfloc.io.estimates.result_row`); also the row of a timeout or error."""
    return result_row(task.dataset_name, task.label, task.scan_id, scan.group if scan else "",
                      true=scan.true if scan else None, init=scan.initial if scan else None)


def failure_row(task: Task, status: Status, scan: Scan | None = None) -> ResultRow:
    """A row for a task that produced no estimate (timeout, crash, error)."""
    if scan is None:
        try:
            scan = load_dataset(task.dataset)[1].get(task.scan_id)
        except Exception:  # noqa: BLE001 - the row must be written whatever went wrong
            scan = None
    return base_row(task, scan).with_(status=status, outcome=NO_ANSWER if scan and scan.true else "")


_WARM: set[tuple[str, str, str]] = set()


def _warm_once(task: Task, matcher, problem) -> None:
    key = (task.dataset, task.matcher, task.params_json)
    if key in _WARM:
        return
    _WARM.add(key)
    try:
        warm(matcher, problem)
    except Exception:  # noqa: BLE001 - the timed call reports what is wrong
        pass


def _posed(task: Task):
    """The task's scan, matcher and problem (raises what building them raises; a global problem
    for a local matcher is an :class:`InvalidProblemError`)."""
    scenario, scans = load_dataset(task.dataset)
    scan = scans[task.scan_id]
    matcher = load_matcher(task.matcher, task.params_json)
    problem = problem_of(scenario, scan)
    check_solvable(matcher, problem)
    return scenario, scan, matcher, problem


def error_status(exc: BaseException) -> Status:
    """The status of a task whose matcher raised ``exc``."""
    return Status.of(StatusKind.ERROR, f"{type(exc).__name__}: {exc}")


def run_task(task: Task) -> ResultRow | list[ResultRow]:
    """Run one task; exceptions from the matcher become an ``error:`` row (never raised), a
    problem the data cannot pose (:class:`InvalidProblemError`) an ``invalid:`` row. A sequence
    task gives one row per scan (:func:`run_sequence_task`)."""
    if task.sequence:
        return run_sequence_task(task)
    scan = load_dataset(task.dataset)[1][task.scan_id]
    try:
        scenario, scan, matcher, problem = _posed(task)
    except InvalidProblemError as exc:
        return failure_row(task, Status.of(StatusKind.INVALID, str(exc)), scan)
    except Exception as exc:  # noqa: BLE001 - a failing matcher is a result, not a crash
        return failure_row(task, error_status(exc), scan)
    try:
        _warm_once(task, matcher, problem_of(scenario, scan))
        timed = timed_localize(matcher, problem)
    except Exception as exc:  # noqa: BLE001 - a failing matcher is a result, not a crash
        return failure_row(task, error_status(exc), scan)
    est = timed.estimate
    status = status_of(est)
    info = est.info if not est.hypotheses else {**est.info, HYPOTHESES_KEY: hypotheses_info(est.hypotheses)}
    row = result_row(task.dataset_name, task.label, task.scan_id, scan.group, true=scan.true,
                     init=scan.initial, est=est.pose, estimate=est, status=status,
                     wall_s=timed.wall_s, cpu_s=timed.cpu_s, info=info)
    if scan.true is None:
        return row
    p, d, o = est.pose, row.dist_err_m, row.orient_err_rad
    s_est = s_true = np.nan
    recorded = ""
    if status.ok and not task.thresholds.success(d, o) and callable(getattr(matcher, "score", None)):
        try:  # why did it fail? the matcher's own objective at its answer and at the truth
            s_est, s_true = float(matcher.score(problem, p)), float(matcher.score(problem, scan.true))
            row = row.with_(score_est=s_est, score_true=s_true)
        except Exception as exc:  # noqa: BLE001
            s_est = s_true = np.nan
            recorded = AMBIGUOUS
            row = row.with_(info={**(row.info or {}), "score_error": str(exc)})
    return row.with_(outcome=outcome(status.ok, d, o, s_est, s_true, task.thresholds, recorded))


def warm_up(task: Task) -> None:
    """Before a run: load the dataset and matcher of ``task``, :func:`warm` them up and run one
    untimed ``localize``, which compiles every numba kernel the matcher uses into numba's on-disk
    cache (other workers then only load them). The caller limits it by runner.WARM_UP_S (or the task's
    limit, if longer), not the task's limit: a cold cache under load must not become timeouts."""
    try:
        scenario, scan, matcher, problem = _posed(task)
        _warm_once(task, matcher, problem_of(scenario, scan))
        matcher.localize(problem)
    except Exception:  # noqa: BLE001 - the real run will report it
        pass


def run_sequence_task(task: Task) -> list[ResultRow]:
    """A whole sequence tracked (:func:`tfloc.harness.track.run_sequence`): one row per scan in
    order, scored by the one rule under the task's thresholds. A matcher that cannot be built is
    one ``error:`` row for the task."""
    from .track import run_sequence

    try:
        return run_sequence(task.dataset, task.label, task.matcher, task.params_json, task.thresholds)
    except Exception as exc:  # noqa: BLE001 - a failing matcher is a result, not a crash
        return [failure_row(task, error_status(exc))]
