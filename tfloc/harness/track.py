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
from tfloc.core.tracker import PREDICTED, DeadReckoning, LocalTracker, as_tracker, is_tracker
from tfloc.errors import DatasetError, InvalidProblemError
from tfloc.io.estimates import COLUMNS, pose_fields
from tfloc.io.scenario import SEQUENCE, Scan, Scenario, map_for

from .workspace import warm

#: status of a row whose estimate is the matcher's own answer / the prediction kept
OK, FAILED = "ok", "failed"


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


def row(dataset: str, label: str, scan: Scan, pred: Pose, est: Pose, status: str, cpu_s: float,
        wall_s: float, estimate: Estimate | None = None, info: dict | None = None) -> dict[str, Any]:
    """One result row of the loop (columns of :data:`tfloc.io.estimates.COLUMNS`)."""
    out = {c: "" for c in COLUMNS}
    out.update(dataset=dataset, scan_id=scan.scan_id, group=scan.group, matcher=label,
               **pose_fields("true", scan.true), **pose_fields("init", pred),
               **pose_fields("est", est), runtime_s=wall_s, cpu_s=cpu_s, status=status)
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
        try:  # untimed: map-only structures and numba kernels, as the runner's warm-up
            problem = Problem(the_map, laser, scans[0].ranges, start, where=where)
            warm(matcher, problem)
            matcher.localize(problem)
        except Exception:  # noqa: BLE001 - the timed steps report what is wrong
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


def dead_reckoning(scenario: Scenario, scans: Sequence[Scan], *, label: str = DeadReckoning.name,
                   dataset: str | None = None) -> list[dict[str, Any]]:
    """The floor every table shows: the prediction alone (the odometry composed from the start
    pose): :func:`track` with the registered matcher ``odometry``
    (:class:`~tfloc.core.tracker.DeadReckoning`)."""
    return track(scenario, scans, DeadReckoning(), label=label, dataset=dataset)


def run_sequence(dataset: str, label: str, matcher: str, params_json: str = "{}") -> list[dict[str, Any]]:
    """One sequence task of a run, as a worker executes it: the dataset ``dataset`` (a directory)
    and the matcher ``matcher`` with ``params_json`` from the worker's workspace, the whole
    sequence tracked; the rows carry ``label`` as their matcher. Dataset errors raise
    :class:`DatasetError`; a matcher that raises on a scan is that scan's ``error:`` row, the
    run goes on."""
    from .workspace import load_dataset, load_matcher, map_of

    scenario, by_id = load_dataset(dataset)
    scans = list(by_id.values())
    return track(scenario, scans, load_matcher(matcher, params_json), label=label,
                 map=map_of(scenario, scans[0]) if scans else None)
