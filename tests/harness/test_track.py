"""The tracking loop (harness/track) and ``tfloc track``: guess = last estimate ⊕ odometry
increment, truth never read, a declining or raising matcher keeps the prediction."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from _paths import ROOT

from tfloc.cli import main
from tfloc.core.matcher import get_matcher
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate
from tfloc.core.thresholds import Thresholds
from tfloc.harness.track import dead_reckoning, track
from tfloc.io.estimates import COLUMNS, to_record
from tfloc.io.scenario import Scan, read_scans, read_scenario, write_scenario

QUICK = ROOT / "data" / "scenarios" / "seq-quick"


def _copy(root: Path, n: int, blank_truth: bool = False) -> Path:
    sc = read_scenario(QUICK)
    scans = read_scans(sc)[:n]
    if blank_truth:
        scans = [Scan(s.scan_id, s.group, s.ranges, s.initial, None, stamp=s.stamp, odom=s.odom) for s in scans]
    return write_scenario(root, "q", sc.map_path, sc.laser, scans, mode="sequence")


class Shift:
    """Answers the guess moved by +1 cm in x; declines scan ids ending in 3; raises on 7."""

    name = "shift"

    def localize(self, problem):
        k = int(problem.where.rsplit(":", 1)[1])
        if k % 10 == 3:
            return Estimate(problem.initial, False, info={"status": "no-answer"})
        if k % 10 == 7:
            raise RuntimeError("boom")
        p = problem.initial
        return Estimate(Pose(p.x + 0.01, p.y, p.theta), True, 1, 1)

    def score(self, problem, pose):
        return 0.0


def test_guess_is_last_estimate_composed_with_odometry(tmp_path):
    sc = read_scenario(_copy(tmp_path / "a", 20))
    scans = read_scans(sc)
    rows = track(sc, scans, Shift())
    assert [r.scan_id for r in rows] == [s.scan_id for s in scans] and list(to_record(rows[0])) == COLUMNS
    for k in range(1, len(rows)):
        last = Pose(rows[k - 1].est_x, rows[k - 1].est_y, rows[k - 1].est_theta)
        want = last.compose(scans[k - 1].odom.between(scans[k].odom))
        assert (rows[k].init_x, rows[k].init_y) == pytest.approx((want.x, want.y), abs=1e-12)
        line = scans[k].line
        if line % 10 == 3:
            assert str(rows[k].status) == "failed" and rows[k].est_x == pytest.approx(want.x)
        elif line % 10 == 7:
            assert str(rows[k].status).startswith("error:RuntimeError: boom")
            assert rows[k].est_x == pytest.approx(want.x)
        else:
            assert str(rows[k].status) == "ok" and rows[k].est_x == pytest.approx(want.x + 0.01)
    for r, scan in zip(rows, scans, strict=True):  # errors where the truth is known; no outcome without thresholds
        est = Pose(r.est_x, r.est_y, r.est_theta)
        assert (r.dist_err_m, r.orient_err_rad) == est.error_to(scan.true) and r.outcome == ""
    scored = track(sc, scans, Shift(), thresholds=Thresholds(0.015, 2.0))
    assert {r.outcome for r in scored} == {"success", "unscored", "no-answer"}


def test_blanked_truth_gives_the_same_estimates(tmp_path):
    """tf-plus on 40 scans of seq-quick, with and without true_*: the same estimates."""
    m = get_matcher("tf-plus")
    a = read_scenario(_copy(tmp_path / "a", 40))
    b = read_scenario(_copy(tmp_path / "b", 40, blank_truth=True))
    ra, rb = track(a, read_scans(a), m), track(b, read_scans(b), m)
    est = lambda rows: np.array([[r.est_x, r.est_y, r.est_theta] for r in rows])  # noqa: E731
    assert np.array_equal(est(ra), est(rb))
    assert all(r.true_x is None for r in rb) and all(r.true_x is not None for r in ra)
    assert [str(r.status) for r in ra] == ["ok"] * 40
    # and it tracks: the answers are near the truth (a test that can fail)
    err = [math.hypot(r.est_x - r.true_x, r.est_y - r.true_y) for r in ra]
    assert max(err) < 0.05


def test_dead_reckoning_is_the_odometry_from_the_start(tmp_path):
    sc = read_scenario(_copy(tmp_path / "a", 30))
    scans = read_scans(sc)
    rows = dead_reckoning(sc, scans)
    end = scans[0].initial.compose(scans[0].odom.between(scans[-1].odom))
    assert (rows[-1].est_x, rows[-1].est_y) == pytest.approx((end.x, end.y), abs=1e-9)
    assert {r.matcher for r in rows} == {"odometry"}


def test_cli_track_writes_est_csv(tmp_path, capsys):
    root = _copy(tmp_path / "a", 12, blank_truth=True)
    out = tmp_path / "est.csv"
    assert main(["track", "--dataset", str(root), "--matcher", "tf-plus", "--out", str(out)]) == 0
    with out.open() as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["scan_id", "est_x", "est_y", "est_theta", "status", "cpu_s"]
    assert len(rows) == 12 and {r["status"] for r in rows} == {"ok"}
    assert main(["track", "--dataset", str(root), "--matcher", "odometry", "--out", str(out)]) == 0


def test_cli_track_one_line_errors(tmp_path, capsys):
    assert main(["track", "--dataset", str(ROOT / "data/scenarios/detail-1"), "--out",
                 str(tmp_path / "e.csv")]) == 2
    err = capsys.readouterr().err
    assert "not a sequence dataset" in err and len(err.strip().splitlines()) == 1
    root = _copy(tmp_path / "a", 5)
    assert main(["track", "--dataset", str(root), "--param", "nope=1", "--out", str(tmp_path / "e.csv")]) == 2
    assert "nope" in capsys.readouterr().err


def test_run_sequence_is_one_task(tmp_path):
    from tfloc.harness.track import run_sequence

    root = _copy(tmp_path / "a", 8)
    rows = run_sequence(str(root), "tfp", "tf-plus", '{"grid_step": 0.1}')
    assert [r.matcher for r in rows] == ["tfp"] * 8 and {str(r.status) for r in rows} == {"ok"}
    odo = run_sequence(str(root), "odometry", "odometry")
    ref = dead_reckoning(read_scenario(root), read_scans(read_scenario(root)))
    pose = lambda r: (r.est_x, r.est_y, r.est_theta)  # noqa: E731
    assert [pose(r) for r in odo] == [pose(r) for r in ref]


def test_rows_are_read_back_by_the_results_reader(tmp_path):
    from tfloc.io.estimates import read_estimates

    sc = read_scenario(_copy(tmp_path / "a", 6))
    rows = track(sc, read_scans(sc), Shift())
    with (tmp_path / "estimates.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, COLUMNS)
        w.writeheader()
        w.writerows(to_record(r) for r in rows)
    df = read_estimates(tmp_path)
    assert len(df) == 6 and set(df["status"]) <= {"ok", "failed", "error:RuntimeError: boom"}


@pytest.mark.parametrize("fault", ["one scan", "no return", "start outside the map"])
def test_unusable_sequences_are_one_line_errors_for_track_and_bench(tmp_path, capsys, fault):
    """Where a recording cannot be tracked at all, `tfloc track` and `tfloc bench` stop before
    running, with one line naming the file (and row)."""
    sc = read_scenario(QUICK)
    scans = read_scans(sc)[:6]
    if fault == "one scan":
        scans, want = scans[:1], "scans.csv: a sequence needs at least 2 scans to track, found 1"
    elif fault == "no return":
        scans = [Scan(s.scan_id, s.group, np.full_like(s.ranges, np.inf), s.initial, s.true, stamp=s.stamp,
                      odom=s.odom) for s in scans]
        want = "scans.csv:2: scan has no return at all"  # the one range rule, at the first row
    else:
        s = scans[0]
        scans[0] = Scan(s.scan_id, s.group, s.ranges, Pose(500.0, 0.0, 0.0), s.true, stamp=s.stamp, odom=s.odom)
        want = f"scans.csv:2: the start pose of {s.scan_id} (500.000, 0.000 m) lies outside the map's known area"
    root = write_scenario(tmp_path / "bad", "bad", sc.map_path, sc.laser, scans, mode="sequence")
    for argv in (["track", "--dataset", str(root), "--matcher", "odometry", "--out", str(tmp_path / "e.csv")],
                 ["bench", str(root), "--matchers", "odometry", "--out", str(tmp_path / "run")]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert want in err and len(err.splitlines()) == 1, err
