"""Kidnapping in tracking: the kidnapped sequences (events recorded, odometry unaware, bundled
bytes regenerated), the kidnap metrics on hand-made trajectories, and the report's kidnap table."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from _committed import assert_same_file
from _paths import SCEN

from tfloc.core.pose import Pose
from tfloc.datasets.kidnap import KIDNAP_BUNDLE, Kidnapping, generate_kidnap_sequences
from tfloc.evaluation.kidnap import (
    false_relocalizations,
    median_scans,
    scans_to_relocalize,
    score_kidnaps,
)
from tfloc.harness.track import odom_deltas
from tfloc.io.estimates import result_row, rows_frame
from tfloc.io.scenario import SEQUENCE, read_scans, read_scenario


# -- metrics on hand-made trajectories ---------------------------------------------------------
def test_scans_to_relocalize_needs_three_correct_scans_in_the_window() -> None:
    ok = np.zeros(40, dtype=bool)
    ok[:10] = True
    ok[14] = True                       # one correct scan, then wrong again: not yet
    ok[17:25] = True                    # back for good 7 scans after the event at 10
    ok[30:32] = True                    # event at 30: two correct scans, then wrong: not held
    assert scans_to_relocalize(ok, [10, 30]) == [7, None]
    ok[30:32] = False
    ok[38:40] = True                    # two correct scans, then the sequence ends: counts
    assert scans_to_relocalize(ok, [10, 30]) == [7, 8]
    ok[38:40] = False
    assert scans_to_relocalize(ok, [10, 30]) == [7, None]
    ok[25:30] = True                    # correct before the next event: not this event's
    assert scans_to_relocalize(ok, [10, 30]) == [7, None]


def test_false_relocalization_is_a_jump_away_from_a_correct_pose() -> None:
    n = 10
    true = np.column_stack([0.1 * np.arange(n), np.zeros(n), np.zeros(n)])
    est = true.copy()
    pred = true.copy()
    est[4] = (5.0, 5.0, 0.0)            # jumped away from a correct pose: false
    est[5:7] = est[4]                   # stays wrong (the prediction follows it: no jump)
    pred[5:7] = est[4]
    est[7] = true[7]                    # jumps back onto the truth from a wrong pose: not false
    pred[7] = est[6]
    ks = score_kidnaps(est, true, pred, [])
    assert ks.false_relocalizations == (4,)
    assert score_kidnaps(est, true, pred, [4]).false_relocalizations == ()   # the kidnap scan itself
    small = est.copy()
    small[4] = true[4] + (0.8, 0.0, 0.0)  # 0.8 m: not a relocalization jump
    assert false_relocalizations(small, pred, np.ones(n, bool) & ~np.isin(np.arange(n), [4, 5, 6])) == []


def test_score_kidnaps_and_median() -> None:
    n = 60
    true = np.column_stack([0.1 * np.arange(n), np.zeros(n), np.zeros(n)])
    true[20:, 1] = 8.0                   # kidnapped at 20 (8 m)
    true[40:, 1] = -6.0                  # and at 40
    est = true.copy()
    est[20:25] = true[19] + (0.1, 0, 0)  # lost for 5 scans, then found
    est[40:] = true[39]                  # never found again
    ks = score_kidnaps(est, true, est, [40, 20])
    assert ks.events == (20, 40) and ks.scans_to_relocalize == (5, None)
    assert ks.recovered_within(20) == 1 and ks.recovered_within(4) == 0
    assert median_scans([5, None]) == math.inf and median_scans([5, 7, None]) == 7.0
    assert math.isnan(median_scans([]))


# -- the datasets ------------------------------------------------------------------------------
@pytest.mark.parametrize("spec", KIDNAP_BUNDLE, ids=lambda s: s.name)
def test_kidnapped_sequences_record_their_events(spec) -> None:
    sc = read_scenario(SCEN / spec.name)
    scans = read_scans(sc)
    kid = Kidnapping()
    assert sc.mode == SEQUENCE and sc.extra["set"] == spec.set and len(scans) >= 500
    ids = [s.scan_id for s in scans]
    events = [ids.index(k) for k in sc.extra["kidnaps"]]
    assert len(events) >= 3 and min(np.diff([0, *events, len(scans)])) >= kid.min_gap
    deltas = odom_deltas(scans)
    for e in events:
        a, b = scans[e - 1].true, scans[e].true
        assert kid.min_m - 0.2 <= a.distance_to(b) <= kid.max_m + 0.2      # moved 5-20 m ...
        assert abs(math.remainder(b.theta - a.theta, 2 * math.pi)) >= math.radians(kid.min_turn_deg) - 0.1
        assert math.hypot(deltas[e].x, deltas[e].y) < 0.3                  # ... unseen by the wheels
    others = [k for k in range(1, len(scans)) if k not in events]
    steps = [scans[k - 1].true.distance_to(scans[k].true) for k in others]
    assert max(steps) < 0.2                                                 # otherwise 10 Hz driving
    sizes = sum((SCEN / d.name / f).stat().st_size for d in KIDNAP_BUNDLE for f in ("scans.csv", "scenario.json"))
    assert sizes <= 5e6


@pytest.mark.bitwise
def test_kidnapped_sequences_regenerate(office_maps) -> None:
    """The bundled seq-kidnap-* are what generate_kidnap_sequences writes (tfloc generate): the
    same bytes, or on another CPU within the last written digit (tests/_committed.py)."""
    generate_kidnap_sequences(office_maps)
    for ds in KIDNAP_BUNDLE:
        for f in ("scans.csv", "scenario.json"):
            assert_same_file(office_maps / "scenarios" / ds.name / f, SCEN / ds.name / f)


# -- the report --------------------------------------------------------------------------------
def test_report_kidnap_table(tmp_path) -> None:
    from _estimates import derive_tracking

    from tfloc.io.tables import KIDNAP
    from tfloc.report.tracking import tracking_section

    name = "seq-kidnap-b"
    sc = read_scenario(SCEN / name)
    scans = read_scans(sc)
    ids = [s.scan_id for s in scans]
    events = [ids.index(k) for k in sc.extra["kidnaps"]]
    rows = []
    for k, s in enumerate(scans):
        # "late" is found 5 scans after every event; "lost" is never found after the first one
        late = s.true if not any(0 <= k - e < 5 for e in events) else s.true.compose(Pose(3.0, 0.0, 0.0))
        lost = s.true if k < events[0] else scans[events[0] - 1].true
        for label, pose in (("late", late), ("lost", lost)):
            rows.append(result_row(name, label, s.scan_id, s.group, true=s.true, init=pose, est=pose,
                                   status="ok", wall_s=0.002, cpu_s=0.002, info={}))
    df = rows_frame(rows)
    rd = derive_tracking(tmp_path, df, {name: sc})
    text = tracking_section(rd, df, {name: sc}, {}, figures=False)
    assert "**kidnap: kidnap events** (1 sequence: seq-kidnap-b)" in text
    late = next(x for x in text.splitlines() if x.startswith("| late") and "/" in x).split("|")
    lost = next(x for x in text.splitlines() if x.startswith("| lost") and "/" in x).split("|")
    n = len(events)
    assert [c.strip() for c in late[2:6]] == [str(n), f"{n}/{n}", "5", "0"]
    assert [c.strip() for c in lost[2:5]] == [str(n), f"0/{n}", "never"]
    ev = rd.frame(KIDNAP)
    assert len(ev) == 2 * n and set(ev["kidnap_scan"]) == set(sc.extra["kidnaps"])
    assert json.loads((SCEN / name / "scenario.json").read_text())["kidnaps"] == sc.extra["kidnaps"]


# -- the recovering tracker --------------------------------------------------------------------
def test_tf_plus_recover_finds_itself_after_a_kidnap_and_tf_plus_does_not() -> None:
    """The development sequence's first kidnap (scan 99): tf-plus-recover, which never reads the
    truth, is correct again within 20 scans without a false jump; tf-plus alone stays lost."""
    from tfloc.core.matcher import get_matcher
    from tfloc.harness.track import track

    sc = read_scenario(SCEN / "seq-kidnap-dev")
    scans = read_scans(sc)[:130]
    event = [s.scan_id for s in scans].index(sc.extra["kidnaps"][0])

    def scored(name: str):
        df = rows_frame(track(sc, scans, get_matcher(name)))
        pose = lambda p: df[[f"{p}_x", f"{p}_y", f"{p}_theta"]].to_numpy(float)  # noqa: E731
        return score_kidnaps(pose("est"), pose("true"), pose("init"), [event]), df

    ks, df = scored("tf-plus-recover")
    assert ks.recovered_within(20) == 1 and ks.false_relocalizations == ()
    info = df["info"].map(json.loads)
    assert not any(info[:event].map(lambda i: i["lost"]))          # no global call while tracking
    assert scored("tf-plus")[0].recovered_within(20) == 0
