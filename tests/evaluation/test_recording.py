"""The recording checks: each rule fires on a made-up sequence with its fault, in the right place,
and stays quiet on a clean one (and on a robot that really stands still); the real MIT CSAIL
odometry freeze is flagged as a stall then a jump; a map that covers part of the route gives
coverage flags; the unusable cases are one-line errors where tracking reads a dataset."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from _paths import ROOT

from tfloc import LaserSpec, load_map
from tfloc.core.pose import Pose
from tfloc.errors import DatasetError
from tfloc.evaluation.recording import check_recording, coverage_flags
from tfloc.io.scenario import SEQUENCE, Scan, Scenario, check_usable, read_scans, read_scenario
from tfloc.maps.build import rasterize
from tfloc.maps.grid import GridMap

ROOM = ROOT / "data" / "maps" / "test-room.geojson"
LASER = LaserSpec(10.0, math.pi, math.radians(1.0), -math.pi / 2)
N = 60


@pytest.fixture(scope="module")
def room():
    return load_map(ROOM)


def route(n: int = N) -> np.ndarray:
    """Along the room's corridor (x 1.6…4.4 m) in 6 s at 10 Hz, turning from 0.3 to 1.5 rad."""
    s = np.linspace(0.0, 1.0, n)
    return np.column_stack((1.6 + 2.8 * s, 4.0 + 0.25 * np.sin(2 * math.pi * s), 0.3 + 1.2 * s))


def sequence(room, poses: np.ndarray, odom: np.ndarray | None = None, seed: int = 3) -> list[Scan]:
    """Scans simulated at ``poses`` with 1 cm noise, 10 Hz stamps, odometry ``odom`` (default:
    the true poses in a frame 2 m and 0.4 rad away, drift-free)."""
    R = room.raycast(poses, LASER)
    R = R + np.random.default_rng(seed).normal(0.0, 0.01, R.shape)
    frame = Pose(-2.0, 1.0, 0.4)
    odom = np.array([frame.compose(Pose(*p)).as_array() for p in poses]) if odom is None else odom
    return [Scan(f"k{k:03d}", "sequence", R[k], Pose(*poses[0]) if k == 0 else None, Pose(*poses[k]),
                 k + 2, stamp=100.0 + 0.1 * k, odom=Pose(*odom[k])) for k in range(len(poses))]


def kinds(check) -> list[tuple[str, str, str]]:
    return [(f.kind, f.first_id, f.last_id) for f in check.flags]


def test_a_clean_sequence_has_no_flags(room) -> None:
    c = check_recording(sequence(room, route()), LASER)
    assert c.flags == () and c.scans == N
    assert c.period_s == pytest.approx(0.1) and c.duration_s == pytest.approx(5.9)
    assert c.summary() == f"{N} scans over 5.9 s (period 0.100 s): no flags"


def test_a_robot_that_stands_still_is_no_stall(room) -> None:
    P = route()
    P = np.vstack([P[:21], np.repeat(P[20:21], 20, axis=0), P[21:]])  # it waits for 2 s at scan 20
    c = check_recording(sequence(room, P), LASER)  # the odometry stands still, the scans but for noise
    assert c.flags == () and c.scans == N + 20


def test_a_scan_gap(room) -> None:
    scans = [s for k, s in enumerate(sequence(room, route())) if not 30 <= k < 40]
    c = check_recording(scans, LASER)
    assert kinds(c) == [("scan-gap", "k029", "k040")]
    assert c.flags[0].duration_s == pytest.approx(1.1) and "11.0 × the median period" in c.flags[0].message


def test_empty_and_sparse_scans(room) -> None:
    scans = sequence(room, route())
    scans[20] = dataclasses.replace(scans[20], ranges=np.full(LASER.n_beams, np.inf))
    scans[21] = dataclasses.replace(scans[21], ranges=np.full(LASER.n_beams, np.inf))
    sparse = np.full(LASER.n_beams, np.inf)
    sparse[:5] = 2.0
    scans[30] = dataclasses.replace(scans[30], ranges=sparse)
    c = check_recording(scans, LASER)
    assert kinds(c) == [("scan-empty", "k020", "k021"), ("scan-sparse", "k030", "k030")]
    assert c.flags[0].scans == 2


def test_missing_odometry(room) -> None:
    scans = sequence(room, route())
    for k in (10, 11, 12):
        scans[k] = dataclasses.replace(scans[k], odom=None)
    assert kinds(check_recording(scans, LASER)) == [("odometry-missing", "k010", "k012")]


def test_a_stall_then_its_catch_up(room) -> None:
    """The odometry freezes for 4 scans while the robot drives on, then reports it all at once."""
    scans = sequence(room, route())
    for k in range(31, 35):
        scans[k] = dataclasses.replace(scans[k], odom=scans[30].odom)
    c = check_recording(scans, LASER)
    assert kinds(c) == [("odometry-stall", "k030", "k034"), ("odometry-jump", "k034", "k035")]
    assert "unchanged over 4 steps" in c.flags[0].message
    assert "caught up" in c.flags[1].message or "after a stall" in c.flags[1].message


def test_an_odometry_jump(room) -> None:
    P = route()
    frame = Pose(-2.0, 1.0, 0.4)
    odom = np.array([frame.compose(Pose(*p)).as_array() for p in P])
    odom[40:, 0] += 1.0  # the odometry leaps 1 m forward between scans 39 and 40
    c = check_recording(sequence(room, P, odom), LASER)
    assert kinds(c) == [("odometry-jump", "k039", "k040")]
    assert "moved 1.0" in c.flags[0].message


def test_the_csail_odometry_freeze_is_a_stall_then_a_jump() -> None:
    """MIT CSAIL's odometry stands still for 4 scans while the robot turns, then reports 85.5° in
    one scan at raw scan 1584 (docs/tracking.md)."""
    sc = read_scenario(ROOT / "data" / "scenarios" / "real-csail-native")
    c = check_recording(read_scans(sc), sc.laser)
    got = kinds(c)
    assert ("odometry-stall", "r01579", "r01583") in got
    assert ("odometry-jump", "r01583", "r01584") in got
    jump = next(f for f in c.flags if f.last_id == "r01584")
    assert "85.5°" in jump.message


def test_a_map_that_covers_part_of_the_route(room) -> None:
    """Right of x = 3 m the grid is unknown (outside-map), or known but without its walls
    (the map explains almost none of what the robot sees there: unmapped-view)."""
    P = route()
    scans = sequence(room, P)
    grid = rasterize(room, 0.05, name="room")
    cx = grid.cell_centres(np.arange(grid.shape[1]), np.zeros(grid.shape[1], dtype=int))[:, 0]
    right = cx > 3.0
    assert coverage_flags(grid, LASER, scans, P) == ()
    unknown = grid.occupancy.copy()
    unknown[:, right] = np.nan
    flags = coverage_flags(GridMap(unknown, grid.resolution, grid.origin, name="half"), LASER, scans, P)
    first = int(np.argmax(right[grid.cell_of(P[:, :2])[0]]))
    assert [(f.kind, f.first, f.last) for f in flags][:1] == [("outside-map", first, N - 1)]
    bare = grid.occupancy.copy()
    bare[:, cx > 2.0] = 0.0  # known free, walls missing
    flags = coverage_flags(GridMap(bare, grid.resolution, grid.origin, name="bare"), LASER, scans, P)
    assert [f.kind for f in flags] and {f.kind for f in flags} == {"unmapped-view"}
    assert max(f.scans for f in flags) >= N // 2 and "of each scan's returns lie within 0.3 m" in flags[0].message
    assert coverage_flags(grid, LASER, scans, [None] * N) == ()  # no poses, no flags


def _scenario(tmp_path) -> Scenario:
    return Scenario("made-up", ROOM, LASER, root=tmp_path, extra={"mode": SEQUENCE})


def test_unusable_sequences_are_one_line_errors(room, tmp_path) -> None:
    sc, scans = _scenario(tmp_path), sequence(room, route(5))
    check_usable(sc, scans, room)
    with pytest.raises(DatasetError, match=r"scans.csv: a sequence needs at least 2 scans to track, found 1"):
        check_usable(sc, scans[:1], room)
    away = [dataclasses.replace(scans[0], initial=Pose(40.0, 3.0, 0.0)), *scans[1:]]
    with pytest.raises(DatasetError, match=r"scans.csv:2: the start pose of k000 \(40.000, 3.000 m\) lies "
                                           r"outside the map's known area"):
        check_usable(sc, away, room)
    for err in (pytest.raises(DatasetError),):
        with err as e:
            check_usable(sc, away, room)
        assert "\n" not in str(e.value)


def test_the_check_recording_verb(room, tmp_path, capsys) -> None:
    """One line per flag and a summary, exit 0 on a usable recording; --poses flags coverage
    for a tracker's answers (a CSV like tfloc track's); a bad file is one line."""
    from tfloc.cli import main
    from tfloc.io.scenario import write_scenario

    scans = sequence(room, route())
    for k in range(31, 35):
        scans[k] = dataclasses.replace(scans[k], odom=scans[30].odom)
    root = write_scenario(tmp_path / "d", "made-up", ROOM, LASER, scans, mode=SEQUENCE)
    assert main(["check-recording", str(root)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("odometry-stall   k030…k034") and out[1].startswith("odometry-jump    k034…k035")
    assert out[-1] == f"made-up: {N} scans over 5.9 s (period 0.100 s): 1 odometry-stall, 1 odometry-jump; usable"
    est = tmp_path / "est.csv"
    est.write_text("scan_id,est_x,est_y,est_theta\n" + "".join(f"{s.scan_id},{s.true.x + (40 if k >= 50 else 0)},"
                                                                 f"{s.true.y},{s.true.theta}\n"
                                                                 for k, s in enumerate(scans)))
    assert main(["check-recording", str(root), "--poses", str(est)]) == 0
    out = capsys.readouterr().out
    assert "outside-map      k050…k059" in out and "1 coverage flag(s)" in out
    est.write_text("scan_id,est_x,est_y,est_theta\nnope,1,2,3\n")
    assert main(["check-recording", str(root), "--poses", str(est)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("est.csv:2: scan_id 'nope' is not a scan of the dataset") and "\n" not in err
