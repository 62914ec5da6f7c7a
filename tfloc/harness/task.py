"""One (scan, matcher) task, executed in a worker process: localize, time, score, classify.

Tasks carry only small data (dataset path, scan id, matcher spec, thresholds); each worker
loads a dataset's scans and map once and keeps them (module-level caches).
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
        the_map = map_for(scenario, scan, _MAPS)
    except Exception as exc:  # noqa: BLE001 - a failing matcher is a result, not a crash
        return failure_row(task, f"error:{type(exc).__name__}: {exc}", scan)
    try:
        problem = Problem(the_map, scenario.laser, scan.ranges, scan.initial,
                          where=f"{scenario.scans_path}:{scan.line}")
    except InvalidProblemError as exc:
        return failure_row(task, f"invalid:{exc}", scan)
    try:
        t0 = time.perf_counter()
        est = matcher.localize(problem)
        runtime = time.perf_counter() - t0
    except Exception as exc:  # noqa: BLE001 - a failing matcher is a result, not a crash
        return failure_row(task, f"error:{type(exc).__name__}: {exc}", scan)
    row = base_row(task, scan)
    p = est.pose
    status = status_of(est)
    declined = status == "failed"
    row.update(est_x=p.x, est_y=p.y, est_theta=p.theta, runtime_s=runtime,
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
    """Load the dataset and matcher of ``task`` (and compile numba kernels) before timing."""
    scenario, scans = load_dataset(task.dataset)
    scan = scans[task.scan_id]
    try:
        m = load_matcher(task.matcher, task.params_json)
        m.score(Problem(map_for(scenario, scan, _MAPS), scenario.laser, scan.ranges, scan.initial),
                scan.initial)
    except Exception:  # noqa: BLE001 - the real run will report it
        pass
