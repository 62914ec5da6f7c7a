"""Corrupt or unsupported bags give one-line errors naming the bag, topic and message index,
through the API (BagError) and through the CLI (exit 2, no traceback)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import _rosbag_cases as cases
import numpy as np
import pytest

from tfloc.cli import main
from tfloc.datasets.from_bag import BagImport, import_bag
from tfloc.errors import BagError, DatasetError, TflocError
from tfloc.io.rosbag import Bag

pytest.importorskip("rosbags")  # the optional extra tfloc[ros]



def _with_gt(items: list) -> list:
    """``items`` and reference poses (PoseStamped on /gt) at the bag's pose stamps."""
    return items + cases.pose_items("/gt", "PoseStamped", cases.POSE_T)


@pytest.fixture(scope="module")
def sim():
    return cases.simulate(12)


def _import(bag: Path, out: Path, map_yaml: Path, **kw) -> None:
    import_bag(BagImport(bag, kw.pop("scan", "/scan"), kw.pop("pose", "/gt"), out, map_file=map_yaml, **kw))


def _cli_error(capsys, argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "Traceback" not in err
    return err


@pytest.mark.parametrize("kind", cases.KINDS)
@pytest.mark.parametrize("frac", [0.5, 0.999])
def test_truncated_bag(tmp_path, sim, map_yaml, capsys, kind, frac) -> None:
    t, P, R = sim
    good = cases.gt_bag(cases.bag_path(tmp_path, kind, "good"), kind, t, R)
    bad = cases.bag_path(tmp_path, kind, "cut")
    if kind == "ros1":
        data = good.read_bytes()
        bad.write_bytes(data[:int(len(data) * frac)])
    else:
        shutil.copytree(good, bad)
        f = next(x for x in bad.iterdir() if x.suffix in (".db3", ".mcap"))
        f.write_bytes(f.read_bytes()[:int(f.stat().st_size * frac)])
    with pytest.raises(BagError) as exc:
        _import(bad, tmp_path / "ds", map_yaml)
    msg = str(exc.value)
    assert str(bad) in msg
    # the index is lost (the bag is named) or a message is unreadable (its topic and index are named)
    assert ("cannot open bag" in msg and "reindex" in msg) or re.search(r"/(scan|gt) (after )?message \d+", msg)
    err = _cli_error(capsys, ["import-bag", str(bad), "--scan-topic", "/scan", "--pose-topic", "/gt",
                              "--map", str(map_yaml), "--out", str(tmp_path / "ds2")])
    assert err.startswith("tfloc import-bag: error:") and str(bad) in err
    assert not (tmp_path / "ds").exists() and not (tmp_path / "ds2").exists()


def test_corrupt_message_names_topic_and_index(tmp_path, sim, map_yaml) -> None:
    """Bytes overwritten inside the mcap data: the message that cannot be decoded is named."""
    t, P, R = sim
    good = cases.write_bag(cases.bag_path(tmp_path, "mcap", "good"), "mcap",
                     cases.scan_items("/scan", t, R) + cases.pose_items("/gt", "PoseStamped", cases.POSE_T))
    bad = cases.bag_path(tmp_path, "mcap", "bad")
    shutil.copytree(good, bad)
    f = next(bad.glob("*.mcap"))
    data = bytearray(f.read_bytes())
    k = data.find(np.asarray(R[3, :8], dtype=np.float32).tobytes())  # scan 3's first ranges
    assert k > 0
    data[k - 8:k] = b"\xff" * 8  # its sequence length and the field before it
    f.write_bytes(bytes(data))
    with pytest.raises(BagError, match=r"/scan message 3: cannot read"):
        _import(bad, tmp_path / "ds", map_yaml)


@pytest.mark.parametrize("kind", ["ros1", "sqlite3"])
def test_missing_topic(tmp_path, sim, map_yaml, capsys, kind) -> None:
    t, P, R = sim
    bag = cases.gt_bag(cases.bag_path(tmp_path, kind), kind, t, R)
    with pytest.raises(BagError, match=r"no topic /ground_truth in the bag \(topics: /gt "):
        _import(bag, tmp_path / "ds", map_yaml, pose="/ground_truth")
    err = _cli_error(capsys, ["import-bag", str(bag), "--scan-topic", "/laser", "--pose-topic", "/gt",
                              "--map", str(map_yaml), "--out", str(tmp_path / "ds")])
    assert "no topic /laser" in err and "/scan [sensor_msgs/msg/LaserScan]" in err


def test_wrong_message_type(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    bag = cases.gt_bag(cases.bag_path(tmp_path, "ros1"), "ros1", t, R)
    with pytest.raises(BagError, match=r"topic /gt has type geometry_msgs/msg/PoseStamped, expected "
                                       r"sensor_msgs/msg/LaserScan"):
        _import(bag, tmp_path / "ds", map_yaml, scan="/gt")
    with pytest.raises(BagError, match=r"topic /scan has type sensor_msgs/msg/LaserScan, expected "
                                       r"geometry_msgs/msg/PoseStamped or "):
        _import(bag, tmp_path / "ds", map_yaml, pose="/scan")


@pytest.mark.parametrize("kind", ["ros1", "mcap"])
def test_nan_angle_increment(tmp_path, sim, map_yaml, capsys, kind) -> None:
    t, P, R = sim
    items = cases.scan_items("/scan", t, R)
    items[4] = type(items[4])("/scan", items[4].t, items[4].ranges, angle_increment=float("nan"))
    bag = cases.write_bag(cases.bag_path(tmp_path, kind), kind, _with_gt(items))
    err = _cli_error(capsys, ["import-bag", str(bag), "--scan-topic", "/scan", "--pose-topic", "/gt",
                              "--map", str(map_yaml), "--out", str(tmp_path / "ds")])
    assert "/scan message 4: angle_increment is nan" in err


def test_varying_beam_count(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    items = cases.scan_items("/scan", t, R)
    items[7] = type(items[7])("/scan", items[7].t, items[7].ranges[:-1])
    bag = cases.write_bag(cases.bag_path(tmp_path, "sqlite3"), "sqlite3", _with_gt(items))
    with pytest.raises(BagError, match=r"/scan message 7: beam count 180 differs from message 0's 181"):
        _import(bag, tmp_path / "ds", map_yaml)


def test_varying_laser_spec(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    items = cases.scan_items("/scan", t, R)
    items[2] = type(items[2])("/scan", items[2].t, items[2].ranges, range_max=30.0)
    bag = cases.write_bag(cases.bag_path(tmp_path, "ros1"), "ros1", _with_gt(items))
    with pytest.raises(BagError, match=r"/scan message 2: range_max 30 differs from message 0's 10"):
        _import(bag, tmp_path / "ds", map_yaml)


def test_poses_that_do_not_cover_the_scans(tmp_path, sim, map_yaml, capsys) -> None:
    t, P, R = sim
    bag = cases.write_bag(cases.bag_path(tmp_path, "mcap"), "mcap",
                    cases.scan_items("/scan", t, R) + cases.pose_items("/gt", "PoseStamped", cases.POSE_T + 10.0))
    err = _cli_error(capsys, ["import-bag", str(bag), "--scan-topic", "/scan", "--pose-topic", "/gt",
                              "--map", str(map_yaml), "--out", str(tmp_path / "ds")])
    assert "/gt covers none of the 12 scans on /scan (scan message 0 at t=" in err
    assert "120 poses" in err


def test_non_finite_pose_names_message(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    poses = cases.pose_items("/gt", "Odometry", cases.POSE_T)
    poses[9] = type(poses[9])("/gt", "Odometry", poses[9].t, (float("inf"), 1.0, 0.0))
    bag = cases.write_bag(cases.bag_path(tmp_path, "ros1"), "ros1", cases.scan_items("/scan", t, R) + poses)
    with pytest.raises(BagError, match=r"/gt message 9: pose is not finite"):
        _import(bag, tmp_path / "ds", map_yaml)


def test_tf_topic_without_the_pair(tmp_path, sim, map_yaml) -> None:
    from _rosbag_cases import TfItem

    t, P, R = sim
    tf = [TfItem("/tf", float(ti), (("odom", "base_link", (0.0, 0.0, 0.0)),)) for ti in cases.POSE_T]
    bag = cases.write_bag(cases.bag_path(tmp_path, "ros1"), "ros1", cases.scan_items("/scan", t, R) + tf)
    with pytest.raises(BagError, match=r"/tf has no transform map → base_link \(frame pairs: odom → base_link\)"):
        _import(bag, tmp_path / "ds", map_yaml, pose="/tf", pose_frames=("map", "base_link"))
    with pytest.raises(BagError, match=r"/tf is a tf topic: name the frame pair"):
        _import(bag, tmp_path / "ds", map_yaml, pose="/tf")


def test_bad_occupancy_grid(tmp_path, sim) -> None:
    t, P, R = sim
    g = cases.room_grid()
    bag = cases.write_bag(cases.bag_path(tmp_path, "ros1"), "ros1",
                    cases.scan_items("/scan", t, R) + [cases.GridItem("/map", cases.T0, g), cases.GridItem("/map", cases.T0 + 1, g)])
    with Bag(bag) as b:  # good: the last of two
        assert b.grid("/map").shape == g.shape
    bad = cases.bag_path(tmp_path, "ros1", "bad")
    data = bytearray(bag.read_bytes())
    occ = np.where(np.isnan(g.occupancy), -1, np.round(100 * np.nan_to_num(g.occupancy))).astype(np.int8)
    k = data.rfind(occ.reshape(-1)[:4000].tobytes())
    assert k > 0
    data[k] = 117  # an occupancy of 117 %
    bad.write_bytes(bytes(data))
    with Bag(bad) as b, pytest.raises(BagError, match=r"/map message 1: cell values must be -1 \(unknown\) or 0…100"):
        b.grid("/map")


def test_existing_dataset_is_not_overwritten(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    bag = cases.gt_bag(cases.bag_path(tmp_path, "ros1"), "ros1", t, R)
    _import(bag, tmp_path / "ds", map_yaml)
    with pytest.raises(DatasetError, match="a dataset exists there already"):
        _import(bag, tmp_path / "ds", map_yaml)


def test_poses_outside_the_map(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    far = [type(p)(p.topic, p.msgtype, p.t, (p.pose[0] + 100, p.pose[1], p.pose[2]))
           for p in cases.pose_items("/gt", "PoseStamped", cases.POSE_T)]
    bag = cases.write_bag(cases.bag_path(tmp_path, "ros1"), "ros1", cases.scan_items("/scan", t, R) + far)
    with pytest.raises(BagError, match=r"none of the /gt poses at the scans lies inside the map"):
        _import(bag, tmp_path / "ds", map_yaml)


def test_missing_bag_and_missing_rosbags(tmp_path, map_yaml, monkeypatch) -> None:
    with pytest.raises(BagError, match="no such bag"):
        _import(tmp_path / "nope.bag", tmp_path / "ds", map_yaml)
    import builtins

    real_import = builtins.__import__

    def fake(name, *a, **kw):
        if name.startswith("rosbags"):
            raise ImportError(name)
        return real_import(name, *a, **kw)

    monkeypatch.setattr(builtins, "__import__", fake)
    with pytest.raises(TflocError, match=r"pip install 'tfloc\[ros\]'"):
        _import(tmp_path / "nope.bag", tmp_path / "ds", map_yaml)


def test_frame_pair_on_a_pose_topic(tmp_path, sim, map_yaml) -> None:
    t, P, R = sim
    bag = cases.gt_bag(cases.bag_path(tmp_path, "ros1"), "ros1", t, R)
    with pytest.raises(BagError, match=r"/gt has type geometry_msgs/msg/PoseStamped; a frame pair applies "
                                       r"to tf topics only"):
        _import(bag, tmp_path / "ds", map_yaml, pose_frames=("map", "base_link"))
