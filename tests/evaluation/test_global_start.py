"""A tracker started without a pose: scans to converge and a first settling on a wrong place, on
hand-made trajectories; how a run says it started without one (AMCL's first row); the report's
start table."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _paths import SCEN

from tfloc.core.pose import Pose
from tfloc.evaluation.global_start import (
    carried,
    first_settled,
    scans_to_converge,
    score_start,
    starts_without_pose,
)
from tfloc.io.estimates import result_row, rows_frame
from tfloc.io.scenario import read_scans, read_scenario


def drive(n: int, step: float = 0.1, turn: float = 0.02) -> np.ndarray:
    """A robot on a gentle curve, ``step`` m and ``turn`` rad a scan."""
    poses = [Pose(1.0, 2.0, 0.3)]
    for _ in range(n - 1):
        poses.append(poses[-1].compose(Pose(step, 0.0, turn)))
    return np.array([p.as_array() for p in poses])


def elsewhere(true: np.ndarray, offset: Pose) -> np.ndarray:
    """The trajectory as seen from a wrong place: every true pose moved by the map-frame ``offset``."""
    return np.array([offset.compose(Pose.from_array(p)).as_array() for p in true])


def test_scans_to_converge_is_the_start_held_for_three_scans() -> None:
    ok = np.zeros(30, dtype=bool)
    ok[5] = True                      # one correct scan: not yet
    ok[9:11] = True                   # two: not yet
    ok[14:20] = True                  # held: converged at 14
    assert scans_to_converge(ok) == 14
    assert scans_to_converge(ok, end=16) == 14   # fewer than 3 before the window ends: counts
    assert scans_to_converge(ok, end=14) is None  # the window ends first: never
    assert scans_to_converge(np.zeros(0, dtype=bool)) is None


def test_carried_place_moves_with_the_robot() -> None:
    true = drive(20)
    off = Pose(3.0, -1.0, 0.7)
    est = elsewhere(true, off)
    c = carried(est, true, 4)
    assert np.allclose(c[:, :2], est[:, :2], atol=1e-9)  # a rigidly wrong estimate is one place
    still = np.repeat(true[:1], 5, axis=0)
    assert np.allclose(carried(still + [0.2, 0, 0], still, 0)[:, :2], still[:, :2] + [0.2, 0])


def test_first_settled_on_a_wrong_place_then_converged() -> None:
    true = drive(60)
    est = true.copy()
    rng = np.random.default_rng(1)
    est[:8] = true[:8] + rng.uniform(-6, 6, (8, 3))           # jumping about: not settled
    est[8:30] = elsewhere(true[8:30], Pose(4.0, 1.0, 0.0))    # a look-alike place, held
    est[30:] = true[30:] + [0.02, -0.01, 0.005]                # then the truth
    s = score_start(est, true)
    assert s.settled == 8 and s.wrong and s.scans_to_converge == 30 and s.window == 60
    assert first_settled(est, true, end=20) == 8
    assert score_start(est, true, end=25).scans_to_converge is None   # before the first kidnap: never
    right = score_start(true + [0.02, 0.0, 0.0], true)
    assert right.settled == 0 and not right.wrong and right.scans_to_converge == 0


def test_a_window_without_truth_does_not_settle() -> None:
    true = drive(15)
    true[5] = np.nan
    assert first_settled(true, true) is None
    assert first_settled(true, true, scans=5) == 0


def test_a_recording_with_sparse_truth_is_scored_on_its_truth_bearing_scans() -> None:
    """A native-rate log: truth on every 4th scan only; the counts are of those scans, the scan
    numbers the recording's."""
    true = drive(240)
    est = true.copy()
    est[:100] = elsewhere(true[:100], Pose(4.0, 1.0, 0.0))    # a wrong place, held
    est[100:] += [0.02, -0.01, 0.005]                         # then the truth
    sparse = np.full_like(true, np.nan)
    sparse[::4] = true[::4]
    s = score_start(est, sparse)
    assert s.window == 240 and s.settled == 0 and s.wrong and s.scans_to_converge == 100
    assert score_start(est, np.full_like(true, np.nan)) == type(s)(240, None, None, False)


def test_starts_without_pose_is_what_the_first_row_says() -> None:
    assert starts_without_pose({"start": "global", "particles": 2000})
    assert not starts_without_pose({}) and not starts_without_pose({"start": "pose"})


def test_amcl_with_global_localization_says_so_in_its_first_row(tmp_path) -> None:
    """The harness passes the first row's pose; AMCL with ``global_localization`` ignores it (a
    pose 13 m away, inside the map as every start must be, changes nothing) and says so, once."""
    from tfloc.baselines.amcl import AmclTracker

    from tfloc.harness.track import track

    sc = read_scenario(SCEN / "seq-quick")
    scans = read_scans(sc)[:12]
    rows = track(sc, scans, AmclTracker(global_localization=True, seed=2))
    far = [type(scans[0])(scans[0].scan_id, scans[0].group, scans[0].ranges, Pose(6.0, 4.0, 2.0),
                          scans[0].true, scans[0].line, stamp=scans[0].stamp, odom=scans[0].odom), *scans[1:]]
    again = track(sc, far, AmclTracker(global_localization=True, seed=2))
    infos = [r.info for r in rows]
    assert infos[0]["start"] == "global" and all("start" not in i for i in infos[1:])
    assert [(r.est_x, r.est_y, r.est_theta) for r in rows] == [(r.est_x, r.est_y, r.est_theta) for r in again]
    local = track(sc, scans[:2], AmclTracker())[0].info
    assert "start" not in local


def _rows(name: str, label: str, poses: np.ndarray, scans, info0: dict) -> list:
    return [result_row(name, label, s.scan_id, s.group, true=s.true, init=Pose.from_array(p),
                       est=Pose.from_array(p), status="ok", wall_s=0.001, cpu_s=0.001,
                       info=info0 if k == 0 else {})
            for k, (s, p) in enumerate(zip(scans, poses, strict=True))]


@pytest.mark.parametrize("global_label", [True, False])
def test_report_start_table(tmp_path, global_label) -> None:
    from tfloc.evaluation.sequences import start_scores
    from tfloc.io.rundir import RunDir
    from tfloc.io.tables import START
    from tfloc.report.tracking import tracking_section

    name = "seq-kidnap-b"
    sc = read_scenario(SCEN / name)
    scans = read_scans(sc)
    true = np.array([s.true.as_array() for s in scans])
    first_kidnap = [s.scan_id for s in scans].index(sc.extra["kidnaps"][0])
    found = true.copy()                                             # wrong for 20 scans, then right
    found[:20] = elsewhere(true[:20], Pose(3.0, 0.0, 0.0))
    never = elsewhere(true, Pose(3.0, 0.0, 0.0))                    # never right
    rows = (_rows(name, "finds", found, scans, {"start": "global"} if global_label else {})
            + _rows(name, "given", true, scans, {}) + _rows(name, "never", never, scans, {}))
    df = rows_frame(rows)
    rd = RunDir(tmp_path)
    starts = start_scores(df, {name: sc.extra})
    if starts:
        rd.write(START, starts)
    text = tracking_section(rd, df, {name: sc}, {}, figures=False)
    if not global_label:
        assert "the start**" not in text and not starts
        return
    assert f"**kidnap: the start** (1 sequence; start window in scans, to the first kidnap or the end: " \
           f"{name} {first_kidnap})" in text
    start = text.split("the start**")[1]
    cells = lambda label: [c.strip() for c in next(x for x in start.splitlines()  # noqa: E731
                                                   if x.startswith(f"| {label} ")).split("|")[2:7]]
    assert cells("finds") == ["none", "1/1", "20", "20", f"1/1 ({name})"]
    assert cells("given") == ["given", "1/1", "0", "0", "0/1"]
    assert cells("never") == ["given", "0/1", "never", "never", "1/1 (seq-kidnap-b)"]
    st = rd.frame(START)
    assert set(st["matcher"]) == {"finds", "given", "never"} and math.isnan(
        st.loc[st["matcher"] == "never", "scans_to_converge"].iloc[0])
