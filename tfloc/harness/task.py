"""One (scan, matcher) task, executed in a worker process: localize, time, score, classify.

Tasks carry only small data (dataset path, scan id, matcher spec, thresholds); each worker
loads a dataset's scans and map once and keeps them (module-level caches).

Timing: ``runtime_s`` is the wall time and ``cpu_s`` the CPU time of the worker process (all its
threads; the workers run one thread each, :mod:`tfloc.harness.threads`) during ``localize``
alone. Before a process times its first task of a dataset and matcher it warms up, untimed
(:func:`warm`): the matcher's ``prepare`` builds what depends only on the map, and one ``score``
loads numba kernels (the runner's :func:`warm_up` has compiled all of them into numba's
cache). A scan-to-scan dataset's map is the reference scan, new for every scan, so its build
stays in every task's time (the warm-up uses a map of its own).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from tfloc.core.matcher import get_matcher
from tfloc.core.pose import Pose, angdiff
from tfloc.core.problem import Estimate, Problem
from tfloc.errors import InvalidProblemError, MatcherError
from tfloc.evaluation.outcome import AMBIGUOUS, NO_ANSWER, Thresholds, outcome
from tfloc.io.scenario import Scan, Scenario, map_for, read_scans, read_scenario


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

    @property
    def key(self) -> tuple[str, str, str]:
        return (self.dataset_name, self.scan_id, self.label)


@lru_cache(maxsize=16)
def load_dataset(path: str) -> tuple[Scenario, dict[str, Scan]]:
    """A dataset's metadata and scans by id, loaded once per worker process."""
    scenario = read_scenario(path)
    return scenario, {s.scan_id: s for s in read_scans(scenario)}


_MAPS: dict = {}


@lru_cache(maxsize=32)
def load_matcher(name: str, params_json: str):
    """A matcher instance, built once per worker; ``module:Class`` names are imported directly
    (the command line allows them only with ``--allow-import``)."""
    params = json.loads(params_json)
    if ":" in name:
        module, _, attr = name.partition(":")
        try:
            factory = getattr(__import__(module, fromlist=[attr]), attr)
        except (ImportError, AttributeError) as exc:
            raise MatcherError(f"matcher {name!r}: cannot import it ({exc})") from None
        return factory(**params)
    return get_matcher(name, **params)


def _pose_fields(prefix: str, p: Pose | None) -> dict[str, Any]:
    if p is None:
        return {f"{prefix}_x": "", f"{prefix}_y": "", f"{prefix}_theta": ""}
    return {f"{prefix}_x": p.x, f"{prefix}_y": p.y, f"{prefix}_theta": p.theta}


def base_row(task: Task, scan: Scan | None) -> dict[str, Any]:
    """The identifying part of a result row (also used for timeout/error rows)."""
    row: dict[str, Any] = {"dataset": task.dataset_name, "scan_id": task.scan_id,
                           "group": scan.group if scan else "", "matcher": task.label}
    row.update(_pose_fields("true", scan.true if scan else None))
    row.update(_pose_fields("init", scan.initial if scan else None))
    if scan is not None and scan.true is not None:
        row["init_dist_err_m"] = scan.initial.distance_to(scan.true)
        row["init_orient_err_rad"] = abs(angdiff(scan.initial.theta, scan.true.theta))
    return row


def failure_row(task: Task, status: str, scan: Scan | None = None) -> dict[str, Any]:
    """A row for a task that produced no estimate (timeout, crash, error)."""
    if scan is None:
        try:
            scan = load_dataset(task.dataset)[1].get(task.scan_id)
        except Exception:  # noqa: BLE001 - the row must be written whatever went wrong
            scan = None
    row = base_row(task, scan)
    row.update(status=status.replace("\n", " ")[:300], outcome=NO_ANSWER if scan and scan.true else "")
    return row


_WARM: set[tuple[str, str, str]] = set()


def problem_of(scenario: Scenario, scan: Scan) -> Problem:
    """The :class:`Problem` of one scan (the dataset's map, or the scan's reference scan)."""
    return Problem(map_for(scenario, scan, _MAPS), scenario.laser, scan.ranges, scan.initial,
                   where=f"{scenario.scans_path}:{scan.line}")


def warm(matcher, problem: Problem) -> None:
    """Untimed warm-up: ``matcher.prepare(problem)`` (map-only structures) if the matcher has one,
    then one ``score`` at the initial pose (kernels compiled or loaded from numba's cache)."""
    prepare = getattr(matcher, "prepare", None)
    if prepare is not None:
        prepare(problem)
    matcher.score(problem, problem.initial)


def _warm_once(task: Task, matcher, scenario: Scenario, scan: Scan) -> None:
    key = (task.dataset, task.matcher, task.params_json)
    if key in _WARM:
        return
    _WARM.add(key)
    try:
        warm(matcher, problem_of(scenario, scan))
    except Exception:  # noqa: BLE001 - the timed call reports what is wrong
        pass


def status_of(est: Estimate) -> str:
    """``failed`` when the matcher declined to answer (``info["status"] == "no-answer"``) or gave a
    non-finite pose, else ``ok``; whether it converged is reported separately."""
    return "failed" if est.info.get("status") == "no-answer" or not est.pose.is_finite() else "ok"


def run_task(task: Task) -> dict[str, Any]:
    """Run one task; exceptions from the matcher become an ``error:`` row (never raised), a
    problem the data cannot pose (:class:`InvalidProblemError`) an ``invalid:`` row."""
    scenario, scans = load_dataset(task.dataset)
    scan = scans[task.scan_id]
    try:
        matcher = load_matcher(task.matcher, task.params_json)
        problem = problem_of(scenario, scan)
    except InvalidProblemError as exc:
        return failure_row(task, f"invalid:{exc}", scan)
    except Exception as exc:  # noqa: BLE001 - a failing matcher is a result, not a crash
        return failure_row(task, f"error:{type(exc).__name__}: {exc}", scan)
    try:
        _warm_once(task, matcher, scenario, scan)
        t0, c0 = time.perf_counter(), time.process_time()
        est = matcher.localize(problem)
        runtime, cpu = time.perf_counter() - t0, time.process_time() - c0
    except Exception as exc:  # noqa: BLE001 - a failing matcher is a result, not a crash
        return failure_row(task, f"error:{type(exc).__name__}: {exc}", scan)
    row = base_row(task, scan)
    p = est.pose
    status = status_of(est)
    declined = status == "failed"
    row.update(est_x=p.x, est_y=p.y, est_theta=p.theta, runtime_s=runtime, cpu_s=cpu,
               converged=int(bool(est.converged)), iterations=est.iterations,
               evaluations=est.evaluations, status=status,
               info=json.dumps(est.info, default=str, separators=(",", ":")))
    if scan.true is None:
        return row
    d, o = p.distance_to(scan.true), abs(angdiff(p.theta, scan.true.theta))
    row.update(dist_err_m=d, orient_err_rad=o)
    if declined or task.thresholds.success(d, o):
        row["outcome"] = outcome(not declined, d, o, np.nan, np.nan, task.thresholds)
        return row
    try:  # why did it fail? compare the matcher's own objective at its answer and at the truth
        s_est, s_true = float(matcher.score(problem, p)), float(matcher.score(problem, scan.true))
        row.update(score_est=s_est, score_true=s_true,
                   outcome=outcome(True, d, o, s_est, s_true, task.thresholds))
    except Exception as exc:  # noqa: BLE001
        row.update(outcome=AMBIGUOUS, info=row["info"][:-1] + f',"score_error":{json.dumps(str(exc))}}}')
    return row


def warm_up(task: Task) -> None:
    """Before a run: load the dataset and matcher of ``task``, :func:`warm` them up and run one
    untimed ``localize``, which compiles every numba kernel the matcher uses into numba's on-disk
    cache (other workers then only load them). The caller gives it the task's time limit."""
    scenario, scans = load_dataset(task.dataset)
    scan = scans[task.scan_id]
    try:
        matcher = load_matcher(task.matcher, task.params_json)
        _warm_once(task, matcher, scenario, scan)
        matcher.localize(problem_of(scenario, scan))
    except Exception:  # noqa: BLE001 - the real run will report it
        pass
