"""The tracking loop: one sequence dataset run with one tracker, scan by scan.

The robot starts at the first row's ``init_*``. A single-scan matcher runs as a
:class:`~tfloc.core.tracker.LocalTracker`. For each scan the loop asks the tracker for its guess
(``predict``: for a local tracker the last estimate ⊕ ``odom(k−1)⁻¹ · odom(k)``; identity for
scan 0), times its ``step`` with the workspace's one timer and writes one row with the one row
builder (:func:`tfloc.io.estimates.result_row`). The truth is never handed to the tracker; it is
copied into the rows to score them.

* ``init_*``: the tracker's prediction; ``est_*``: its answer (the prediction when it kept it:
  ``failed``, or when the step raised: ``error:<message>``, and the loop resets the tracker to
  the prediction and goes on);
* ``cpu_s``/``runtime_s``: CPU and wall time of the step alone (the tracker's ``warm`` runs
  untimed before the sequence);
* errors where the truth is known, and the ``outcome`` of the one rule when thresholds are given
  (a tracking loop has no objective to tell a local optimum: such a failure is unscored).

A tracker that answers the whole sequence at once (an external program,
:func:`tfloc.core.external.is_batch_tracker`) is run once (:func:`batch_steps`); its rows are
built the same way, ``init_*`` its previous answer ⊕ the odometry increment, ``cpu_s`` its share
of the child process's CPU time (``info["cpu_from"]`` says how it was split) and ``runtime_s``
the same share of the child's wall time. A program that fails makes every row ``error:<its
message>`` at the prediction (dead reckoning from the start).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from tfloc.core.external import is_batch_tracker
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate
from tfloc.core.result import ResultRow, Status, StatusKind
from tfloc.core.thresholds import Thresholds
from tfloc.core.tracker import DeadReckoning, as_tracker
from tfloc.errors import DatasetError
from tfloc.evaluation.outcome import outcome
from tfloc.io.estimates import result_row
from tfloc.io.scenario import SEQUENCE, Scan, Scenario, check_usable, map_for

from .workspace import status_of, timed_step, warm_tracker


def check_sequence(scenario: Scenario, scans: Sequence[Scan], the_map=None) -> None:
    """Raise :class:`DatasetError` unless ``scans`` are a sequence the loop can run (and, given
    ``the_map``, one that starts inside it: :func:`tfloc.io.scenario.check_usable`)."""
    if scenario.mode != SEQUENCE:
        raise DatasetError(f"{scenario.root}: not a sequence dataset (mode {scenario.mode!r}); "
                           "tracking needs \"mode\": \"sequence\" in scenario.json")
    if not scans or scans[0].initial is None:
        raise DatasetError(f"{scenario.scans_path}: a sequence needs a first row with init_x/y/theta")
    check_usable(scenario, scans, the_map)


def odom_deltas(scans: Sequence[Scan]) -> list[Pose]:
    """The odometry increment of each scan (robot frame of the previous scan); identity for the
    first scan."""
    out = [Pose()]
    for prev, cur in zip(scans[:-1], scans[1:], strict=True):
        out.append(prev.odom.between(cur.odom))
    return out


def track(scenario: Scenario, scans: Sequence[Scan], matcher, *, label: str | None = None,
          dataset: str | None = None, map=None, thresholds: Thresholds | None = None,
          progress: Callable[[int], None] | None = None) -> list[ResultRow]:
    """Run ``matcher`` (a single-scan matcher or a :class:`~tfloc.core.tracker.Tracker`) along
    the sequence ``scans`` of ``scenario``; one row per scan, in order (module notes).
    ``map`` overrides the dataset's map; ``thresholds`` fill each scored row's ``outcome``;
    ``progress(k)`` is called after each scan."""
    check_sequence(scenario, scans)
    tracker = as_tracker(matcher)
    label = label or getattr(tracker, "name", type(matcher).__name__)
    dataset = dataset or scenario.name
    the_map = map if map is not None else map_for(scenario, scans[0], {})
    check_sequence(scenario, scans, the_map)
    if is_batch_tracker(tracker):
        steps = iter(batch_steps(tracker, scenario, scans, the_map, scans[0].initial))
        next_step = lambda scan, delta: next(steps)  # noqa: E731
    else:
        begin(tracker, scenario, scans, the_map)
        next_step = lambda scan, delta: step(tracker, scenario, scan, delta)  # noqa: E731
    rows = []
    for k, (scan, delta) in enumerate(zip(scans, odom_deltas(scans), strict=True)):
        s = next_step(scan, delta)
        row = result_row(dataset, label, scan.scan_id, scan.group, true=scan.true, init=s.pred, est=s.pose,
                         estimate=s.estimate, status=s.status, wall_s=s.wall_s, cpu_s=s.cpu_s,
                         info=dict(s.estimate.info) if s.estimate is not None else {})
        if thresholds is not None and scan.true is not None:
            row = row.with_(outcome=outcome(s.status.ok, row.dist_err_m, row.orient_err_rad,
                                            math.nan, math.nan, thresholds))
        rows.append(row)
        if progress is not None:
            progress(k)
    return rows


def begin(tracker, scenario: Scenario, scans: Sequence[Scan], the_map) -> None:
    """Warm a tracker up (untimed) and start it at the sequence's first pose."""
    start = scans[0].initial
    warm_tracker(tracker, the_map, scenario.laser, scans[0].ranges, start)
    tracker.start(the_map, scenario.laser, start)


@dataclass(frozen=True)
class Step:
    """One step of a tracker: its prediction, its answer (the prediction where it declined, gave
    no finite pose or raised, and it was reset there), the estimate (``None`` if it raised), the
    status and the step's wall and CPU time (seconds; ``None`` if it raised)."""

    pred: Pose
    pose: Pose
    estimate: Estimate | None
    status: Status
    wall_s: float | None
    cpu_s: float | None


def step(tracker, scenario: Scenario, scan: Scan, delta: Pose) -> Step:
    """One scan of the tracking loop: predict, a timed ``step``, reset to the prediction where
    the answer is no pose or the tracker raised (the loop goes on)."""
    pred = tracker.predict(delta)
    where = f"{scenario.scans_path}:{scan.line}"
    try:
        t = timed_step(tracker, scan.ranges, delta, scan.stamp, where)
    except Exception as exc:  # noqa: BLE001 - a raising tracker is a result; the run goes on
        tracker.reset(pred)
        return Step(pred, pred, None, Status.of(StatusKind.ERROR, f"{type(exc).__name__}: {exc}"), None, None)
    pose = t.estimate.pose
    if not pose.is_finite():
        pose = pred
        tracker.reset(pred)
    return Step(pred, pose, t.estimate, status_of(t.estimate), t.wall_s, t.cpu_s)


def batch_steps(tracker, scenario: Scenario, scans: Sequence[Scan], the_map, start: Pose) -> list[Step]:
    """The steps of a tracker that answers ``scans`` at once (``run_batch``), started at
    ``start``: each step's prediction is the previous answer ⊕ the odometry increment (``start``
    for the first), its answer the program's pose (the prediction where that is not finite). A
    program that raises gives every step an ``error:`` status at the dead-reckoned prediction."""
    deltas = odom_deltas(scans)
    odometry = np.array([[s.odom.x, s.odom.y, s.odom.theta] for s in scans], dtype=float)
    stamps = np.array([s.stamp for s in scans], dtype=float)
    try:
        ans = tracker.run_batch(the_map, scenario.laser, [s.ranges for s in scans], stamps, odometry, start)
    except Exception as exc:  # noqa: BLE001 - a failing program is a result, every row says why
        status, out, pose = Status.of(StatusKind.ERROR, f"{type(exc).__name__}: {exc}"), [], start
        for k, delta in enumerate(deltas):
            pose = start if k == 0 else pose.compose(delta)
            out.append(Step(pose, pose, None, status, None, None))
        return out
    n = len(scans)
    wall = ans.cpu_per_scan_s * (ans.wall_s / ans.cpu_s) if ans.cpu_s > 0 else np.full(n, ans.wall_s / n)
    out, prev = [], start
    for k, delta in enumerate(deltas):
        pred = start if k == 0 else prev.compose(delta)
        info = {**(ans.info[k] if k < len(ans.info) else {}), "cpu_from": ans.cpu_from}
        pose = Pose(*map(float, ans.poses[k]))
        est = Estimate(pose, True, info=info)
        if not pose.is_finite():
            pose = pred
        out.append(Step(pred, pose, est, status_of(est), float(wall[k]), float(ans.cpu_per_scan_s[k])))
        prev = pose
    return out


def dead_reckoning(scenario: Scenario, scans: Sequence[Scan], *, label: str = DeadReckoning.name,
                   dataset: str | None = None) -> list[ResultRow]:
    """The floor every table shows: the prediction alone (the odometry composed from the start
    pose): :func:`track` with the registered matcher ``odometry``
    (:class:`~tfloc.core.tracker.DeadReckoning`)."""
    return track(scenario, scans, DeadReckoning(), label=label, dataset=dataset)


def run_sequence(dataset: str, label: str, matcher: str, params_json: str = "{}",
                 thresholds: Thresholds | None = None) -> list[ResultRow]:
    """One sequence task of a run, as a worker executes it: the dataset ``dataset`` (a directory)
    and the matcher ``matcher`` with ``params_json`` from the worker's workspace, the whole
    sequence tracked; the rows carry ``label`` as their matcher. Dataset errors raise
    :class:`DatasetError`; a tracker that raises on a scan is that scan's ``error:`` row, the
    run goes on."""
    from tfloc.io.scenario import load_dataset

    from .workspace import load_matcher, map_of

    scenario, by_id = load_dataset(dataset)
    scans = list(by_id.values())
    return track(scenario, scans, load_matcher(matcher, params_json), label=label,
                 map=map_of(scenario, scans[0]) if scans else None, thresholds=thresholds)
