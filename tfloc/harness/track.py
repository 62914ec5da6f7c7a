"""The tracking loop: one sequence dataset run with one matcher (or tracker), scan by scan.

The robot starts at the first row's ``init_*``; the guess for scan k is the estimate of scan k−1
composed with the odometry increment ``odom(k−1)⁻¹ · odom(k)`` (:mod:`tfloc.core.tracker`; for
scan 0 the increment is the identity). The truth is never read by the loop: ``true_*`` is only
copied into the rows so that they can be scored later (:mod:`tfloc.evaluation.trajectory`).

One row per scan, in order, in the columns of :data:`tfloc.io.estimates.COLUMNS`:

* ``init_*``: the prediction handed to the matcher; ``est_*``: its answer, or the prediction
  when it declined (``status`` = ``failed``), when the prediction posed no problem (it left the
  map: ``failed``, ``info.reason``) or when it raised (``status`` = ``error:<message>``; the run
  goes on from the prediction);
* ``cpu_s``/``runtime_s``: process CPU time and wall time of the step alone (the matcher's
  ``prepare``, one ``score`` and one ``localize`` of the first scan run untimed before it);
* ``dist_err_m``, ``orient_err_rad``, ``init_*_err``, ``outcome``, ``score_*``: left empty.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from typing import Any

from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem
from tfloc.core.tracker import PREDICTED, LocalTracker, as_tracker, is_tracker
from tfloc.errors import DatasetError, InvalidProblemError
from tfloc.io.estimates import COLUMNS
from tfloc.io.scenario import SEQUENCE, Scan, Scenario, map_for

#: status of a row whose estimate is the matcher's own answer / the prediction kept
OK, FAILED = "ok", "failed"
#: the matcher name of dead reckoning (the prediction alone), the floor of every tracking table
DEAD_RECKONING = "odometry"


def check_sequence(scenario: Scenario, scans: Sequence[Scan]) -> None:
    """Raise :class:`DatasetError` unless ``scans`` are a sequence the loop can run."""
    if scenario.mode != SEQUENCE:
        raise DatasetError(f"{scenario.root}: not a sequence dataset (mode {scenario.mode!r}); "
                           "tracking needs \"mode\": \"sequence\" in scenario.json")
    if not scans or scans[0].initial is None:
        raise DatasetError(f"{scenario.scans_path}: a sequence needs a first row with init_x/y/theta")


def odom_deltas(scans: Sequence[Scan]) -> list[Pose]:
    """The odometry increment of each scan (robot frame of the previous scan); identity for the
    first scan."""
    out = [Pose()]
    for prev, cur in zip(scans[:-1], scans[1:], strict=True):
        out.append(prev.odom.between(cur.odom))
    return out


def _pose_fields(prefix: str, p: Pose | None) -> dict[str, Any]:
    if p is None:
        return {f"{prefix}_x": "", f"{prefix}_y": "", f"{prefix}_theta": ""}
    return {f"{prefix}_x": p.x, f"{prefix}_y": p.y, f"{prefix}_theta": p.theta}


def _warm(matcher, problem: Problem) -> None:
    """Untimed: ``prepare`` (map-only structures), one ``score`` and one ``localize`` (numba
    kernels compiled or loaded), as the runner's warm-up does before a run."""
    try:
        prepare = getattr(matcher, "prepare", None)
        if prepare is not None:
            prepare(problem)
        matcher.score(problem, problem.initial)
        matcher.localize(problem)
    except Exception:  # noqa: BLE001 - the timed steps report what is wrong
        pass


def row(dataset: str, label: str, scan: Scan, pred: Pose, est: Pose, status: str, cpu_s: float,
        wall_s: float, estimate: Estimate | None = None, info: dict | None = None) -> dict[str, Any]:
    """One result row of the loop (columns of :data:`tfloc.io.estimates.COLUMNS`)."""
    out = {c: "" for c in COLUMNS}
    out.update(dataset=dataset, scan_id=scan.scan_id, group=scan.group, matcher=label,
               **_pose_fields("true", scan.true), **_pose_fields("init", pred),
               **_pose_fields("est", est), runtime_s=wall_s, cpu_s=cpu_s, status=status)
    if estimate is not None:
        out.update(converged=int(bool(estimate.converged)), iterations=estimate.iterations,
                   evaluations=estimate.evaluations)
    out["info"] = json.dumps(info or {}, default=str, sort_keys=True)
    return out


def track(scenario: Scenario, scans: Sequence[Scan], matcher, *, label: str | None = None,
          dataset: str | None = None, map=None,
          progress: Callable[[int], None] | None = None) -> list[dict[str, Any]]:
    """Run ``matcher`` (a single-scan matcher or a :class:`~tfloc.core.tracker.Tracker`) along
    the sequence ``scans`` of ``scenario``; one row per scan, in order (module notes).
    ``map`` overrides the dataset's map; ``progress(k)`` is called after each scan."""
    check_sequence(scenario, scans)
    name = getattr(matcher, "name", type(matcher).__name__)
    label = label or name
    dataset = dataset or scenario.name
    the_map = map if map is not None else map_for(scenario, scans[0], {})
    laser = scenario.laser
    start = scans[0].initial
    if not is_tracker(matcher):
        where = f"{scenario.scans_path}:{scans[0].line}"
        try:
            _warm(matcher, Problem(the_map, laser, scans[0].ranges, start, where=where))
        except InvalidProblemError:
            pass
    tracker = as_tracker(matcher)
    tracker.start(the_map, laser, start)
    rows = []
    last = start
    for k, (scan, delta) in enumerate(zip(scans, odom_deltas(scans), strict=True)):
        pred = last.compose(delta)
        where = f"{scenario.scans_path}:{scan.line}"
        info: dict[str, Any] = {}
        est: Estimate | None = None
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            est = (tracker.step(scan.ranges, delta, scan.stamp, where=where)
                   if isinstance(tracker, LocalTracker) else tracker.step(scan.ranges, delta, scan.stamp))
            status = FAILED if est.info.get("status") == PREDICTED else OK
            pose = est.pose if est.pose.is_finite() else pred
            info = dict(est.info)
        except InvalidProblemError as exc:
            status, pose, info = FAILED, pred, {"status": PREDICTED, "reason": str(exc)[:200]}
        except Exception as exc:  # noqa: BLE001 - a raising matcher is a result; the run goes on
            status = f"error:{type(exc).__name__}: {exc}".replace("\n", " ")[:300]
            pose = pred
        cpu, wall = time.process_time() - c0, time.perf_counter() - t0
        if pose is pred and hasattr(tracker, "reset"):
            tracker.reset(pred)
        rows.append(row(dataset, label, scan, pred, pose, status, cpu, wall, est, info))
        last = pose
        if progress is not None:
            progress(k)
    return rows


def dead_reckoning(scenario: Scenario, scans: Sequence[Scan], *, label: str = DEAD_RECKONING,
                   dataset: str | None = None) -> list[dict[str, Any]]:
    """The floor every table shows: the prediction alone (the odometry composed from the start
    pose), as rows of a matcher named ``odometry`` (status ``ok``, CPU time 0)."""
    check_sequence(scenario, scans)
    dataset = dataset or scenario.name
    rows, last = [], scans[0].initial
    for scan, delta in zip(scans, odom_deltas(scans), strict=True):
        pred = last.compose(delta)
        rows.append(row(dataset, label, scan, pred, pred, OK, 0.0, 0.0))
        last = pred
    return rows


def run_sequence(dataset: str, label: str, matcher: str, params_json: str = "{}") -> list[dict[str, Any]]:
    """One sequence task of a run, as a worker executes it: load the dataset ``dataset`` (a
    directory), build the registered ``matcher`` with ``params_json`` (``odometry``: dead
    reckoning) and track the whole sequence; the rows carry ``label`` as their matcher. Dataset
    errors raise :class:`DatasetError`; a matcher that raises on a scan is that scan's
    ``error:`` row, the run goes on."""
    from tfloc.core.matcher import get_matcher
    from tfloc.io.scenario import read_scans, read_scenario

    scenario = read_scenario(dataset)
    scans = read_scans(scenario)
    if matcher == DEAD_RECKONING:
        return dead_reckoning(scenario, scans, label=label)
    return track(scenario, scans, get_matcher(matcher, **json.loads(params_json)), label=label)
