"""The re-convergence restarts of the truth-free verdict: a tracker started afresh at perturbed
poses of its own trajectory and run a few scans (:mod:`tfloc.evaluation.truthfree.reconverge`).

Each restart uses the tracking loop's own step (:func:`tfloc.harness.track.step`: predict, the
tracker's step, reset to the prediction where it raised), so a restarted tracker sees exactly
what it saw in the run: the same scans, the same odometry increments, never the truth. A tracker
that answers whole sequences (an external program) is run once per restart on the restart's
slice of the sequence (:func:`tfloc.harness.track.batch_steps`), started at the perturbed pose.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tfloc.core.external import is_batch_tracker
from tfloc.core.pose import Pose
from tfloc.core.tracker import as_tracker
from tfloc.evaluation.truthfree.reconverge import Restart
from tfloc.io.scenario import Scan, Scenario

from .track import batch_steps, odom_deltas, step
from .workspace import warm_tracker


def restart_ends(scenario: Scenario, scans: Sequence[Scan], matcher, own: np.ndarray,
                 restarts: Sequence[Restart], the_map) -> np.ndarray:
    """``(R, 3)`` the last answer of each restart of ``matcher`` (a tracker or a single-scan
    matcher) along ``scans``, started at ``own[first] ⊕ offset`` (``own`` ``(N, 3)``: its answers
    in the run); NaN where a restart could not start."""
    out = np.full((len(restarts), 3), np.nan)
    if not restarts:
        return out
    tracker = as_tracker(matcher)
    if is_batch_tracker(tracker):
        for r, rs in enumerate(restarts):
            start = Pose(*own[rs.first]).compose(rs.offset)
            if start.is_finite():
                pose = batch_steps(tracker, scenario, scans[rs.first:rs.last + 1], the_map, start)[-1].pose
                out[r] = (pose.x, pose.y, pose.theta)
        return out
    deltas = odom_deltas(scans)
    first = restarts[0]
    warm_tracker(tracker, the_map, scenario.laser, scans[first.first].ranges,
                 Pose(*own[first.first]).compose(first.offset))
    for r, rs in enumerate(restarts):
        start = Pose(*own[rs.first]).compose(rs.offset)
        if not start.is_finite():
            continue
        tracker.start(the_map, scenario.laser, start)
        pose = start
        for k in range(rs.first, rs.last + 1):
            pose = step(tracker, scenario, scans[k], Pose() if k == rs.first else deltas[k]).pose
        out[r] = (pose.x, pose.y, pose.theta)
    return out
