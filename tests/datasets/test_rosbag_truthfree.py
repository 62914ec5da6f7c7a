"""`tfloc import-bag` without reference poses (what a robot owner has: scans, odometry, a map): a
sequence with empty truth whose start comes from --initial-pose, --initial-topic or a global
matcher (stated, with its score and whether it is ambiguous), that tracks; odometry gaps are
skipped and recorded; unusable recordings are one-line errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from _rosbag_cases import (
    LASER,
    POSE_T,
    T0,
    PoseItem,
    bag_path,
    pose_items,
    scan_items,
    simulate,
    write_bag,
)

from tfloc.cli import main
from tfloc.core.matcher import get_matcher
from tfloc.core.pose import Pose, angdiff
from tfloc.datasets.from_bag import BagImport, import_bag
from tfloc.errors import BagError, ConfigError
from tfloc.harness.track import track
from tfloc.io.scenario import read_scans, read_scenario

pytest.importorskip("rosbags")  # the optional extra tfloc[ros]

ODOM_FRAME = Pose(-3.0, 2.0, 0.7)  # where the odom frame's origin is in the map
AMCL_OFF = np.array([0.03, -0.02, 0.01])


def _odom(t: np.ndarray) -> list[PoseItem]:
    return [PoseItem("/odom", "Odometry", a.t, tuple(ODOM_FRAME.inverse().compose(Pose(*a.pose)).as_array()), "odom")
            for a in pose_items("/odom", "Odometry", t)]


def _amcl(t: np.ndarray) -> list[PoseItem]:
    return [PoseItem(a.topic, a.msgtype, a.t, tuple(np.add(a.pose, AMCL_OFF)), a.frame)
            for a in pose_items("/amcl_pose", "PoseWithCovarianceStamped", t)]


@pytest.fixture(scope="module")
def sim():
    return simulate(20)


@pytest.fixture(scope="module")
def bag(tmp_path_factory, sim) -> Path:
    """Scans, odometry and AMCL's poses from 0.5 s on: no reference poses."""
    t, P, R = sim
    tmp = tmp_path_factory.mktemp("bag")
    return write_bag(bag_path(tmp, "mcap"), "mcap",
                     scan_items("/scan", t, R) + _odom(POSE_T) + _amcl(POSE_T[POSE_T > T0 + 0.5]))


def _cli(bag: Path, out: Path, map_yaml: Path, *extra: str) -> int:
    return main(["import-bag", str(bag), "--scan-topic", "/scan", "--odom-topic", "/odom", "--map", str(map_yaml),
                 "--out", str(out), *extra])


def _check(out: Path, sim, first: int = 0) -> tuple[dict, list]:
    """A sequence without truth whose odometry increments are the true ones."""
    t, P, R = sim
    sc = read_scenario(out)
    scans = read_scans(sc)
    assert sc.mode == "sequence" and sc.extra["truth"] is False and sc.has_truth is False
    assert all(s.true is None for s in scans)
    assert [s.scan_id for s in scans] == [f"s{k:05d}" for k in range(first, len(t))]
    assert scans[0].initial is not None and all(s.initial is None for s in scans[1:])
    for k, (a, b) in enumerate(zip(scans[:-1], scans[1:], strict=True)):
        d_odom = a.odom.between(b.odom)
        d_true = Pose(*P[first + k]).between(Pose(*P[first + k + 1]))
        assert d_odom.distance_to(d_true) < 3e-4 and abs(angdiff(d_odom.theta, d_true.theta)) < 1e-5
    return json.loads((out / "scenario.json").read_text()), scans


def test_the_start_from_initial_pose(tmp_path, sim, bag, map_yaml, capsys) -> None:
    t, P, R = sim
    assert _cli(bag, tmp_path / "ds", map_yaml, "--initial-pose", *map(str, P[0])) == 0
    printed = capsys.readouterr().out
    assert "no truth (true_* empty)" in printed and "from initial-pose" in printed
    assert "recording checks: 20 scans over 1.9 s (period 0.100 s): no flags" in printed
    doc, scans = _check(tmp_path / "ds", sim)
    assert scans[0].initial.distance_to(Pose(*P[0])) < 1e-6
    assert doc["generator"]["start"]["source"] == "initial-pose"
    # it tracks (harness.track.track), and tf-plus-track follows the robot from that start
    rows = track(read_scenario(tmp_path / "ds"), scans, get_matcher("tf-plus-track"))
    assert len(rows) == len(t) and all(r.status.ok for r in rows)
    assert all(r.true_x is None and r.dist_err_m is None for r in rows)  # no truth, no error
    assert max(math.hypot(r.est_x - p[0], r.est_y - p[1]) for r, p in zip(rows, P, strict=True)) < 0.05


def test_the_start_from_an_initial_topic(tmp_path, sim, bag, map_yaml, capsys) -> None:
    """AMCL's poses begin at 0.5 s: the sequence starts at the first scan they cover."""
    t, P, R = sim
    assert _cli(bag, tmp_path / "ds", map_yaml, "--initial-topic", "/amcl_pose") == 0
    assert "5 outside /amcl_pose before its first pose" in capsys.readouterr().out
    doc, scans = _check(tmp_path / "ds", sim, first=5)
    np.testing.assert_allclose(scans[0].initial.as_array(), P[5] + AMCL_OFF, atol=3e-4)
    assert doc["generator"]["start"] == {"source": "initial-topic", "from": "/amcl_pose",
                                         "pose": pytest.approx(list(P[5] + AMCL_OFF), abs=3e-4)}
    assert doc["source"]["skipped"]["before_initial"] == 5


def test_the_start_found_by_a_global_matcher(tmp_path, sim, bag, map_yaml, capsys) -> None:
    t, P, R = sim
    assert _cli(bag, tmp_path / "ds", map_yaml) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if "found by" in ln)
    assert "found by tf-global on the first 3 scans (score " in line and "AMBIGUOUS" not in line
    doc, scans = _check(tmp_path / "ds", sim)
    start = doc["generator"]["start"]
    assert start["source"] == "global-matcher" and start["from"] == "tf-global" and start["scans"] == 3
    assert start["ambiguous"] is False and start["score"] < start["runner_up"]["score"] / 1.5
    assert scans[0].initial.distance_to(Pose(*P[0])) < 0.05
    assert abs(angdiff(scans[0].initial.theta, P[0, 2])) < math.radians(2)


def test_a_symmetric_room_makes_the_global_start_ambiguous(tmp_path) -> None:
    """In a bare rectangle a pose and its half-turn about the centre see the same scan."""
    from tfloc import load_map
    from tfloc.datasets.first_pose import global_first_pose
    from tfloc.maps.build import rasterize

    (tmp_path / "box.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [
            [[0, 0], [7, 0], [7, 4], [0, 4], [0, 0]]]}}]}))
    box = rasterize(load_map(tmp_path / "box.geojson"), 0.05, name="box")
    P = np.array([[2.0, 1.5, 0.3], [2.1, 1.52, 0.32], [2.2, 1.54, 0.34]])
    start = global_first_pose(box, LASER, box.raycast(P, LASER), [Pose(*p) for p in P], where="box")
    assert start.ambiguous and start.runner_up is not None
    twin = Pose(7.0 - 2.0, 4.0 - 1.5, 0.3 + math.pi)
    assert min(start.pose.distance_to(p) for p in (Pose(*P[0]), twin)) < 0.1
    assert "AMBIGUOUS" in start.text()


def test_odometry_gaps_are_skipped_and_recorded(tmp_path, sim, map_yaml, capsys) -> None:
    t, P, R = sim
    hole = (POSE_T > t[8] - 0.015) & (POSE_T < t[12] + 0.015)  # no odometry around scans 8…12
    bag = write_bag(bag_path(tmp_path, "ros1"), "ros1", scan_items("/scan", t, R) + _odom(POSE_T[~hole]))
    assert _cli(bag, tmp_path / "ds", map_yaml, "--initial-pose", *map(str, P[0]), "--max-pose-gap", "0.2") == 0
    printed = capsys.readouterr().out
    assert "/odom missing for 5 scans in 1 stretch(es): messages 8…12 (0.40 s)" in printed
    assert "recording checks: 15 scans over 1.9 s (period 0.100 s): 1 scan-gap" in printed
    doc = json.loads((tmp_path / "ds" / "scenario.json").read_text())
    assert doc["generator"]["odometry_gaps"] == [{"first_message": 8, "last_message": 12, "scans": 5,
                                                  "from_s": pytest.approx(t[8]), "to_s": pytest.approx(t[12]),
                                                  "seconds": 0.4}]
    assert doc["source"]["skipped"]["outside_odom"] == 5


def _one_line_error(capsys, argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "Traceback" not in err
    return err


def test_no_reference_poses_and_no_odometry_is_an_error(tmp_path, bag, map_yaml, capsys) -> None:
    err = _one_line_error(capsys, ["import-bag", str(bag), "--scan-topic", "/scan", "--map", str(map_yaml),
                                   "--out", str(tmp_path / "ds")])
    assert "a single-scan dataset needs reference poses (--pose-topic)" in err
    assert "--odom-topic" in err and "--initial-pose" in err and "--initial-topic" in err
    with pytest.raises(ConfigError, match="a single-scan dataset needs reference poses"):
        BagImport(bag, "/scan", None, tmp_path / "ds", map_file=map_yaml)
    with pytest.raises(ConfigError, match="--initial-pose is the start of a sequence without reference poses"):
        BagImport(bag, "/scan", "/gt", tmp_path / "ds", map_file=map_yaml, initial_pose=Pose(1.0, 1.0, 0.0))
    with pytest.raises(ConfigError, match="not a global matcher"):
        import_bag(BagImport(bag, "/scan", None, tmp_path / "ds", map_file=map_yaml, odom_topic="/odom",
                             initial_matcher="tf"))
    assert not (tmp_path / "ds").exists()


def test_unusable_recordings_are_one_line_errors(tmp_path, sim, bag, map_yaml, capsys) -> None:
    err = _one_line_error(capsys, ["import-bag", str(bag), "--scan-topic", "/scan", "--odom-topic", "/odom",
                                   "--map", str(map_yaml), "--out", str(tmp_path / "a"),
                                   "--initial-pose", "40", "3", "0"])
    assert str(bag) in err and "the start pose of s00000 (40.000, 3.000 m) lies outside the map's known area" in err
    with pytest.raises(BagError, match=r"a sequence needs at least 2 scans to track, found 1"):
        import_bag(BagImport(bag, "/scan", None, tmp_path / "b", map_file=map_yaml, odom_topic="/odom",
                             initial_pose=Pose(*sim[1][0]), limit=1))
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()
