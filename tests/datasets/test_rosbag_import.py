"""`tfloc import-bag`: ROS 1 and ROS 2 (sqlite3, mcap) bags written with rosbags' own writers,
holding LaserScans simulated in the test room, reference poses of every kind and a map, become
scenario datasets whose scans, stamps and poses are those of the bag."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from _rosbag_cases import (
    KINDS,
    LASER,
    POSE_T,
    ROOM,
    T0,
    GridItem,
    TfItem,
    bag_path,
    path_pose,
    pose_items,
    room_grid,
    scan_items,
    simulate,
    write_bag,
)

from tfloc import load_map
from tfloc.cli import main
from tfloc.core.pose import Pose, angdiff
from tfloc.datasets.from_bag import BagImport, import_bag
from tfloc.io.rosbag import Bag
from tfloc.io.scenario import read_scans, read_scenario

pytest.importorskip("rosbags")  # the optional extra tfloc[ros]

POSE_TYPES = ("PoseStamped", "PoseWithCovarianceStamped", "Odometry")


@pytest.fixture(scope="module")
def sim():
    return simulate(20)


def _check_dataset(out: Path, sim, tol_xy: float = 2e-4) -> list:
    t, P, R = sim
    sc = read_scenario(out)
    scans = read_scans(sc)
    assert sc.laser.n_beams == LASER.n_beams
    assert sc.laser.angle_min == pytest.approx(LASER.angle_min, abs=1e-6)
    assert sc.laser.resolution == pytest.approx(LASER.resolution, abs=1e-8)
    assert sc.laser.max_range == LASER.max_range
    assert len(scans) == len(t)
    for k, s in enumerate(scans):
        assert s.scan_id == f"s{k:05d}"
        assert s.stamp == pytest.approx(t[k], abs=2e-6)
        np.testing.assert_allclose(s.ranges, R[k], atol=1e-4)  # float32 in the bag, 0.1 mm in the csv
        assert math.hypot(s.true.x - P[k, 0], s.true.y - P[k, 1]) < tol_xy
        assert abs(angdiff(s.true.theta, P[k, 2])) < 1e-6
    return scans


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("ptype", POSE_TYPES)
def test_scans_and_poses_round_trip(tmp_path, sim, map_yaml, kind, ptype) -> None:
    t, P, R = sim
    bag = write_bag(bag_path(tmp_path, kind), kind,
                    scan_items("/scan", t, R) + pose_items("/ground_truth", ptype, POSE_T))
    out = tmp_path / "ds"
    assert main(["import-bag", str(bag), "--scan-topic", "/scan", "--pose-topic", "/ground_truth",
                 "--map", str(map_yaml), "--out", str(out)]) == 0
    scans = _check_dataset(out, sim)
    doc = json.loads((out / "scenario.json").read_text())
    assert doc["source"]["angle_increment"] == pytest.approx(LASER.resolution, abs=1e-8)
    assert doc["source"]["range_max"] == LASER.max_range
    assert doc["source"]["skipped"] == {"outside_poses": 0, "outside_initial": 0, "no_return": 0}
    # the map is copied into the dataset, which is self-contained
    assert (out / "room.yaml").is_file() and (out / "room.pgm").is_file()
    assert np.array_equal(load_map(out / "room.yaml").occupied, room_grid().occupied)
    # initial poses: the paper's bins around the truth, free, balanced
    groups = [s.group for s in scans]
    assert set(groups) <= {f"d{i}-a{j}" for i in (1, 2, 3) for j in (1, 2, 3)}
    for s in scans:
        i, j = int(s.group[1]), int(s.group[4])
        assert i - 1 <= s.true.distance_to(s.initial) <= i
        assert math.radians(5 * (j - 1)) <= abs(angdiff(s.initial.theta, s.true.theta)) <= math.radians(5 * j)


@pytest.mark.parametrize("kind", ["sqlite3", "mcap"])
def test_ros2_storage_file_given_directly(tmp_path, sim, kind) -> None:
    t, P, R = sim
    bag = write_bag(bag_path(tmp_path, kind), kind, scan_items("/scan", t, R))
    f = next(x for x in bag.iterdir() if x.suffix in (".db3", ".mcap"))
    with Bag(f) as b:
        np.testing.assert_allclose(b.scans("/scan").ranges, R, atol=1e-5)


def test_perturbation_is_seeded(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    bag = write_bag(bag_path(tmp_path, "ros1"), "ros1", scan_items("/scan", t, R)
                    + pose_items("/gt", "PoseStamped", POSE_T))

    def run(name: str, seed: int) -> list:
        import_bag(BagImport(bag, "/scan", "/gt", tmp_path / name, map_file=map_yaml, seed=seed))
        return [s.initial for s in read_scans(read_scenario(tmp_path / name))]

    a, b, c = run("a", 7), run("b", 7), run("c", 8)
    assert a == b and a != c
    assert (tmp_path / "a" / "scans.csv").read_bytes() == (tmp_path / "b" / "scans.csv").read_bytes()


@pytest.mark.parametrize("kind", ["ros1", "mcap"])
def test_tf_frame_pair_and_occupancy_grid_topic(tmp_path, sim, kind) -> None:
    """Reference poses from /tf (map → base_link among other pairs), map from /map."""
    t, P, R = sim
    tf = [TfItem("/tf", float(ti), (("odom", "base_link", (0.1, 0.0, 0.0)), ("map", "base_link", tuple(p))))
          for ti, p in zip(POSE_T, path_pose(POSE_T), strict=True)]
    bag = write_bag(bag_path(tmp_path, kind), kind,
                    scan_items("/scan", t, R) + tf + [GridItem("/map", T0, room_grid())])
    out = tmp_path / "ds"
    assert main(["import-bag", str(bag), "--scan-topic", "/scan", "--pose-topic", "/tf",
                 "--pose-frames", "map", "base_link", "--map-topic", "/map", "--out", str(out)]) == 0
    _check_dataset(out, sim)
    grid = load_map(out / "map.yaml")
    ref = room_grid()
    assert grid.shape == ref.shape and grid.origin == pytest.approx(ref.origin)
    assert np.array_equal(grid.occupied, ref.occupied) and np.array_equal(grid.free, ref.free)
    # the inverse pair gives the inverse transform
    with Bag(bag) as b:
        inv = b.poses("/tf", ("base_link", "map"))
    k = 17
    assert Pose.from_array(inv.poses[k]).compose(Pose.from_array(path_pose(POSE_T[k:k + 1])[0])) \
        .distance_to(Pose()) < 1e-9


def test_initial_topic_and_alignment(tmp_path, sim, map_yaml) -> None:
    """--initial-topic: AMCL-like poses in the map frame are used as they are; odometry in
    its own frame is aligned to the reference at the first scan with --align-initial."""
    t, P, R = sim
    amcl_off = np.array([0.05, -0.03, 0.02])
    amcl = pose_items("/amcl_pose", "PoseWithCovarianceStamped", POSE_T)
    amcl = [type(a)(a.topic, a.msgtype, a.t, tuple(np.add(a.pose, amcl_off)), a.frame) for a in amcl]
    odom_frame = Pose(-3.0, 2.0, 0.7)  # where the odom frame's origin is in the map
    odom = [type(a)("/odom", "Odometry", a.t, tuple(odom_frame.inverse().compose(Pose(*a.pose)).as_array()),
                    "odom") for a in pose_items("/odom", "Odometry", POSE_T)]
    bag = write_bag(bag_path(tmp_path, "sqlite3"), "sqlite3",
                    scan_items("/scan", t, R) + pose_items("/gt", "PoseStamped", POSE_T) + amcl + odom)
    import_bag(BagImport(bag, "/scan", "/gt", tmp_path / "amcl", map_file=map_yaml, initial_topic="/amcl_pose"))
    scans = read_scans(read_scenario(tmp_path / "amcl"))
    for s in scans:
        d = s.initial.as_array() - s.true.as_array()
        np.testing.assert_allclose(d, amcl_off, atol=3e-4)
        assert s.group == "amcl_pose"
    import_bag(BagImport(bag, "/scan", "/gt", tmp_path / "odom", map_file=map_yaml, initial_topic="/odom",
                         align_initial=True))
    for s in read_scans(read_scenario(tmp_path / "odom")):  # drift-free odometry: aligned = truth
        assert s.initial.distance_to(s.true) < 3e-4 and abs(angdiff(s.initial.theta, s.true.theta)) < 1e-6


def test_scans_outside_the_pose_stream_are_skipped_and_counted(tmp_path, sim, map_yaml, capsys) -> None:
    t, P, R = sim
    pt = POSE_T[(POSE_T > t[5] - 0.015) & (POSE_T < t[16] + 0.015)]  # covers scans 5…16
    bag = write_bag(bag_path(tmp_path, "mcap"), "mcap",
                    scan_items("/scan", t, R) + pose_items("/gt", "PoseStamped", pt))
    out = tmp_path / "ds"
    assert main(["import-bag", str(bag), "--scan-topic", "/scan", "--pose-topic", "/gt",
                 "--map", str(map_yaml), "--out", str(out)]) == 0
    assert "skipped 8 outside /gt" in capsys.readouterr().out
    scans = read_scans(read_scenario(out))
    assert [s.scan_id for s in scans] == [f"s{k:05d}" for k in range(5, 17)]
    assert json.loads((out / "scenario.json").read_text())["source"]["skipped"]["outside_poses"] == 8


def test_pose_gaps_every_limit_and_laser_offset(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    pt = POSE_T[(POSE_T < t[8]) | (POSE_T > t[11])]  # a 0.3 s hole around scans 8…11
    bag = write_bag(bag_path(tmp_path, "ros1"), "ros1",
                    scan_items("/scan", t, R) + pose_items("/gt", "PoseStamped", pt))
    s = import_bag(BagImport(bag, "/scan", "/gt", tmp_path / "a", map_file=map_yaml, max_pose_gap_s=0.2))
    assert (s.kept, s.outside_poses) == (16, 4)
    s = import_bag(BagImport(bag, "/scan", "/gt", tmp_path / "b", map_file=map_yaml, every=3, limit=4))
    assert [x.scan_id for x in read_scans(read_scenario(tmp_path / "b"))] == ["s00000", "s00003", "s00006",
                                                                               "s00009"]
    off = Pose(0.2, 0.0, 0.0)
    import_bag(BagImport(bag, "/scan", "/gt", tmp_path / "c", map_file=map_yaml, laser_offset=off, limit=3))
    for k, sc in enumerate(read_scans(read_scenario(tmp_path / "c"))):
        assert sc.true.distance_to(Pose.from_array(P[k]).compose(off)) < 2e-4


def test_range_conversion_and_mirrored_scanner(tmp_path, sim, map_yaml) -> None:
    """NaN, below range_min and above range_max become inf; a negative angle_increment is
    stored counter-clockwise."""
    t, P, R = sim
    Rb = R.copy()
    Rb[:, 0], Rb[:, 1], Rb[:, 2] = np.nan, 0.01, 12.0
    bag = write_bag(bag_path(tmp_path, "ros1"), "ros1", scan_items("/scan", t, Rb)
                    + scan_items("/scan_mirrored", t, R[:, ::-1], angle_min=-LASER.angle_min,
                                 angle_increment=-LASER.resolution)
                    + pose_items("/gt", "PoseStamped", POSE_T))
    with Bag(bag) as b:
        s = b.scans("/scan")
        m = b.scans("/scan_mirrored")
    assert np.isinf(s.ranges[:, :3]).all()
    np.testing.assert_allclose(s.ranges[:, 3:], R[:, 3:], atol=1e-5)
    assert m.laser.angle_min == pytest.approx(LASER.angle_min, abs=1e-6)
    assert m.laser.resolution == pytest.approx(LASER.resolution, abs=1e-8)
    np.testing.assert_allclose(m.ranges, R, atol=1e-5)


def test_imported_scans_fit_the_map(tmp_path, sim, map_yaml) -> None:
    """The imported scans at their reference poses agree with the map's virtual sensor."""
    bag = write_bag(bag_path(tmp_path, "sqlite3"), "sqlite3",
                    scan_items("/scan", sim[0], sim[2]) + pose_items("/gt", "Odometry", POSE_T))
    import_bag(BagImport(bag, "/scan", "/gt", tmp_path / "ds", map_file=map_yaml))
    sc = read_scenario(tmp_path / "ds")
    room = load_map(ROOM)
    for s in read_scans(sc):
        ok = sc.laser.valid(s.ranges)
        sim_r = room.raycast(s.true, sc.laser)
        assert np.median(np.abs(s.ranges[ok] - sim_r[ok])) < 1e-3


def test_bench_runs_on_an_imported_dataset(tmp_path, sim, map_yaml) -> None:
    """End to end: bag → import-bag → bench → export → evo reads the estimates (needs the
    harness runner; the run configuration follows benchmarks/*.toml)."""
    pytest.importorskip("tfloc.harness.runner")
    file_interface = pytest.importorskip("evo.tools.file_interface")
    bag = write_bag(bag_path(tmp_path, "mcap"), "mcap",
                    scan_items("/scan", sim[0], sim[2]) + pose_items("/gt", "PoseStamped", POSE_T))
    ds = tmp_path / "scenarios" / "mybag"
    assert main(["import-bag", str(bag), "--scan-topic", "/scan", "--pose-topic", "/gt",
                 "--map", str(map_yaml), "--out", str(ds), "--limit", "3", "--seed", "1"]) == 0
    run = tmp_path / "results" / "mybag"
    cfg = tmp_path / "mybag.toml"
    cfg.write_text(f'name = "mybag"\nout = "{run}"\ndatasets = ["{ds}"]\nmatchers = ["tf"]\n'
                   'jobs = 1\ntimeout_s = 120\n')
    assert main(["bench", str(cfg), "--jobs", "1"]) == 0
    assert main(["export", str(run), "--tum", str(tmp_path / "tum"), "--datasets", str(ds.parent)]) == 0
    scans = read_scans(read_scenario(ds))
    ref = file_interface.read_tum_trajectory_file(str(tmp_path / "tum" / "mybag" / "reference.tum"))
    np.testing.assert_allclose(ref.timestamps, [s.stamp for s in scans], atol=1e-6)
    np.testing.assert_allclose(ref.positions_xyz[:, :2], [[s.true.x, s.true.y] for s in scans], atol=1e-6)
    est = file_interface.read_tum_trajectory_file(str(tmp_path / "tum" / "mybag" / "tf.tum"))
    assert 1 <= est.num_poses <= len(scans)


@pytest.mark.parametrize("how", ["odometry", "tf"])
def test_odometry_topic_makes_a_sequence(tmp_path, sim, map_yaml, how) -> None:
    """--odom-topic: a sequence dataset; the odometry (in its own frame) is read at the scan
    stamps, its increments are the true ones, and `tfloc track` runs on it."""
    t, P, R = sim
    odom_frame = Pose(-3.0, 2.0, 0.7)  # where the odom frame's origin is in the map
    in_odom = [odom_frame.inverse().compose(Pose(*p)) for p in path_pose(POSE_T)]
    if how == "odometry":
        items = [type(a)("/odom", "Odometry", a.t, tuple(o.as_array()), "odom")
                 for a, o in zip(pose_items("/odom", "Odometry", POSE_T), in_odom, strict=True)]
        args = ["--odom-topic", "/odom"]
    else:
        items = [TfItem("/tf", float(ti), (("odom", "base_link", tuple(o.as_array())),))
                 for ti, o in zip(POSE_T, in_odom, strict=True)]
        args = ["--odom-topic", "/tf", "--odom-frames", "odom", "base_link"]
    bag = write_bag(bag_path(tmp_path, "mcap"), "mcap",
                    scan_items("/scan", t, R) + pose_items("/gt", "PoseStamped", POSE_T) + items)
    out = tmp_path / "seq"
    assert main(["import-bag", str(bag), "--scan-topic", "/scan", "--pose-topic", "/gt",
                 "--map", str(map_yaml), "--out", str(out), *args]) == 0
    sc = read_scenario(out)
    assert sc.mode == "sequence"
    scans = _check_dataset(out, sim)
    assert scans[0].initial is not None and all(s.initial is None for s in scans[1:])
    for a, b in zip(scans[:-1], scans[1:], strict=True):
        d_odom, d_true = a.odom.between(b.odom), a.true.between(b.true)
        assert d_odom.distance_to(d_true) < 3e-4 and abs(angdiff(d_odom.theta, d_true.theta)) < 1e-5
    assert main(["track", "--dataset", str(out), "--matcher", "odometry", "--out", str(tmp_path / "e.csv")]) == 0


def test_odometry_topic_excludes_initial_poses(tmp_path, map_yaml) -> None:
    from tfloc.errors import ConfigError

    with pytest.raises(ConfigError, match="--odom-topic writes a sequence"):
        BagImport(tmp_path / "x.bag", "/scan", "/gt", tmp_path / "o", map_file=map_yaml,
                  initial_topic="/amcl_pose", odom_topic="/odom")
