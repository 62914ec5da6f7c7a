"""The truth-free verdict's signals, their combination, its interval and its check against the
truth, on hand-made answers (tfloc.evaluation.truthfree)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tfloc.core.laser import LaserSpec
from tfloc.evaluation.truthfree import belief as B
from tfloc.evaluation.truthfree import odometry as O
from tfloc.evaluation.truthfree import reconverge as R
from tfloc.evaluation.truthfree.agreement import agreement, tracker_checks
from tfloc.evaluation.truthfree.config import TruthFreeConfig
from tfloc.evaluation.truthfree.consensus import consensus
from tfloc.evaluation.truthfree.judge import judge, verdict_rows
from tfloc.evaluation.truthfree.mapfit import fit_shares, scan_points
from tfloc.evaluation.truthfree.score import block_bootstrap, share

CFG = TruthFreeConfig()


def _path(n: int) -> np.ndarray:
    t = np.arange(n, dtype=float)
    return np.stack([0.1 * t, np.zeros(n), np.zeros(n)], axis=1)


def test_consensus_leaves_the_tracker_out_and_counts_methods_once() -> None:
    """Three methods on the truth and one 1 m off: the three agree, the off one disagrees; two
    configurations of one method are one witness; dead reckoning (None) never votes."""
    n = 5
    good = _path(n)
    off = good + [1.0, 0.0, 0.0]
    poses = np.stack([good, good, good, off])
    agree, known, support = consensus(poses, ["a", "b", "c", "d"], 0.1, math.radians(2), 2)
    assert known.all()
    assert agree[:3].all() and not agree[3].any()
    assert (support[3] == 3).all() and (support[0] == 2).all()
    # a and a' (one method) are no consensus for c: one witness method only
    agree, known, _ = consensus(np.stack([good, good, off]), ["a", "a", "c"], 0.1, math.radians(2), 2)
    assert not known[2].any()
    _, known, _ = consensus(np.stack([good, good, good]), ["a", None, "c"], 0.1, math.radians(2), 2)
    assert not known[0].any() and not known[2].any()  # one witness method left for a and c ...
    assert known[1].all()  # ... while dead reckoning itself is judged by both


def test_two_rival_groups_are_no_consensus() -> None:
    n = 3
    a, b = _path(n), _path(n) + [2.0, 0.0, 0.0]
    _, known, _ = consensus(np.stack([a, a, b, b, a]), ["p", "q", "r", "s", "t"], 0.1, 0.05, 2)
    assert not known[4].any()  # for t: {p, q} against {r, s}


def test_map_fit_is_high_at_the_true_pose_and_low_off_it() -> None:
    """Ranges cast in a 10 m × 6 m room fit the map at the pose they were cast from, not 0.5 m off."""
    from shapely.geometry import box

    from tfloc.core.pose import Pose
    from tfloc.maps.fields import distance_field
    from tfloc.maps.vector import VectorMap

    room = VectorMap(outline=box(-5, -3, 5, 3))
    laser = LaserSpec.lms200()
    r = room.raycast(Pose(0.0, 0.0, 0.3), laser)
    pts = scan_points(np.asarray(r)[None, :], laser)
    field = distance_field(room, 0.025, cap=0.2, pad=1.0)
    at = fit_shares(pts, np.array([[0.0, 0.0, 0.3]]), field, 0.05)
    off = fit_shares(pts, np.array([[0.5, 0.3, 0.3]]), field, 0.05)
    assert at[0] > 0.97 and off[0] < 0.3
    assert math.isnan(fit_shares(pts, np.array([[np.nan, 0.0, 0.0]]), field, 0.05)[0])


def test_odometry_envelope_and_disagreement() -> None:
    est = np.zeros((1, 100, 3))
    init = est.copy()
    init[0, :, 0] = 0.01  # a 1 cm correction everywhere ...
    init[0, 50, 0] = 0.6  # ... and one of 60 cm
    d, t = O.corrections(est, init)
    env = O.envelope(d, t, np.ones_like(d, bool), 0.99, 0.05, math.radians(1))
    assert env[0] == pytest.approx(0.05)  # the floor: 99 % of 1 cm corrections
    dis = O.disagrees(d, t, env, 2.0)
    assert dis[0].sum() == 1 and dis[0, 50]


def test_belief_without_consensus_needs_a_near_best_fit_and_the_odometry() -> None:
    fits = np.array([[0.9, 0.9, 0.5], [0.85, 0.6, 0.5]])
    known = np.zeros_like(fits, bool)
    odo = np.array([[False, True, False], [False, False, False]])
    b = B.believed(np.zeros_like(known), known, fits, odo, 0.10)
    assert b.tolist() == [[True, False, True], [True, False, True]]
    # where there is a consensus, it decides
    b = B.believed(np.array([[False, True, True], [True, True, True]]), np.ones_like(known), fits, odo, 0.1)
    assert b.tolist() == [[False, True, True], [True, True, True]]


def test_block_bootstrap_interval() -> None:
    v = np.r_[np.ones(500), np.zeros(500)]
    lo, hi = block_bootstrap(v, 50, 2000, 0)
    assert lo < 0.5 < hi and hi - lo < 0.5
    assert all(math.isnan(x) for x in block_bootstrap(np.ones(60), 50, 100, 0))
    s, lo, hi = share(np.ones(200, bool), 50, 500, 0)
    assert (s, lo, hi) == (1.0, 1.0, 1.0)


def test_judge_finds_the_tracker_that_jumps_to_the_next_corridor() -> None:
    """Four independent trackers on one path; one jumps 2 m sideways halfway and stays there: it
    is believed lost from the jump on, the others tracked; its jump is counted."""
    n = 200
    good = _path(n)
    bad = good.copy()
    bad[100:, 1] += 2.0
    est = np.stack([good, good, good, bad])
    init = est.copy()
    init[:, 1:] = est[:, :-1] + [0.1, 0.0, 0.0]  # the prediction: last answer + the odometry
    init[:, 0] = est[:, 0]
    fit = np.where(np.arange(n)[None, :] >= 100, [[0.9], [0.9], [0.9], [0.3]], 0.9)
    j = judge(est, init, fit, ["a", "b", "c", "d"], CFG)
    assert j.believed[:3].all()
    assert j.believed[3, :100].all() and not j.believed[3, 100:].any()
    rows = verdict_rows("rec", ["a", "b", "c", "d"], j, CFG)
    assert rows[3].score_pct == pytest.approx(50.0) and rows[3].jumps == 1
    assert rows[0].score_pct == 100.0 and rows[0].jumps == 0


def test_agreement_agrees_and_disagrees() -> None:
    """The check can fail: a verdict that ranks the trackers upside down DISAGREES."""
    n = 100
    has = np.ones(n, bool)
    tracked = np.stack([np.arange(n) < k for k in (95, 70, 40)])
    checks = tracker_checks("r", ["a", "b", "c"], [94.0, 71.0, 39.0], tracked, tracked, has)
    a = agreement("r", checks, tracked, has)
    assert a.rho == pytest.approx(1.0) and a.top == "same" and a.agrees and a.wrong_pct == 0
    wrong = ~tracked
    checks = tracker_checks("r", ["a", "b", "c"], [5.0, 30.0, 60.0], wrong, tracked, has)
    a = agreement("r", checks, tracked, has)
    assert a.rho == pytest.approx(-1.0) and a.top == "different" and not a.agrees
    assert a.missed_losses + a.false_alarms == int(wrong.size)


def test_restarts_plan_and_return() -> None:
    plan = R.plan(100, 4, 30, 0.3, math.radians(5), 0)
    assert [p.first for p in plan] == [0, 23, 46, 69] and all(p.last == p.first + 29 for p in plan)
    assert all(math.hypot(p.offset.x, p.offset.y) == pytest.approx(0.3) for p in plan)
    assert R.plan(20, 4, 30, 0.3, 0.1, 0) == ()
    own = np.zeros((3, 3))
    ends = np.array([[0.05, 0.0, 0.0], [0.3, 0.0, 0.0], [np.nan, 0, 0]])
    assert R.returned(ends, own, 0.1, math.radians(2)).tolist() == [True, False, False]
