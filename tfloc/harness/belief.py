"""Taking a tracker's belief at one scan while it tracks (``tfloc track --draw-at SCAN_ID``): the
snapshot of its optional read-only accessors right after the step (:func:`take_snapshot`) and
the tracking loop's callback that takes it at a scan, or at the first lost one (:class:`Watch`).
What the snapshot holds and says: :mod:`tfloc.evaluation.belief`."""

from __future__ import annotations

import numpy as np

from tfloc.core.pose import Pose
from tfloc.evaluation.belief import Snapshot, is_lost, probe_poses


def take_snapshot(tracker, index: int, scan_id: str, ranges: np.ndarray, angles: np.ndarray,
                  estimate: Pose, truth: Pose | None, info: dict) -> Snapshot:
    """The tracker's belief right after its step at scan ``index`` (module notes)."""
    belief = getattr(tracker, "belief", None)
    got = belief() if callable(belief) else None
    particles, weights = (None, None) if got is None else (np.asarray(got[0], float), np.asarray(got[1], float))
    factors, probes = None, ()
    like = getattr(tracker, "likelihood", None)
    if callable(like) and particles is not None:
        factors = np.asarray(like(particles), float)
        named = probe_poses(truth, estimate)
        values = np.asarray(like(np.array([p.as_array() for _, p in named])), float)
        probes = tuple((n, p, float(v)) for (n, p), v in zip(named, values, strict=True))
    last = getattr(tracker, "last_motion", None)
    motion = last() if callable(last) else None
    return Snapshot(index, str(scan_id), estimate, truth, np.asarray(ranges, float), np.asarray(angles, float),
                    dict(info), particles, weights, factors, probes, motion)


#: ``--draw-at first-loss``: the first scan whose estimate is lost (truth known, > 0.5 m or 10°)
FIRST_LOSS = "first-loss"


class Watch:
    """The tracking loop's ``progress`` callback that takes one :class:`Snapshot`: after the step
    at scan index ``target``, or with ``target`` :data:`FIRST_LOSS` at the first scan whose
    estimate is lost. The estimate is read as ``tracker.predict(Pose())`` (the belief carried by
    no motion); :meth:`result` completes the snapshot from the loop's row."""

    def __init__(self, tracker, scans, angles: np.ndarray, target: int | str) -> None:
        self.tracker, self.scans, self.angles, self.target = tracker, scans, angles, target
        self.snapshot: Snapshot | None = None

    def __call__(self, k: int) -> None:
        if self.snapshot is not None:
            return
        scan = self.scans[k]
        if self.target != k and self.target != FIRST_LOSS:
            return
        est = self.tracker.predict(Pose())
        if self.target == FIRST_LOSS and not is_lost(est, scan.true):
            return
        self.snapshot = take_snapshot(self.tracker, k, scan.scan_id, scan.ranges, self.angles, est, scan.true, {})

    def result(self, rows: list) -> Snapshot | None:
        """The snapshot with the row's estimate, prediction and ``info`` (rows:
        :class:`~tfloc.core.result.ResultRow`); ``None`` if none was taken."""
        import dataclasses

        if self.snapshot is None:
            return None
        r = rows[self.snapshot.index]
        return dataclasses.replace(self.snapshot, estimate=Pose(r.est_x, r.est_y, r.est_theta),
                                   prediction=Pose(r.init_x, r.init_y, r.init_theta), info=dict(r.info or {}))
