"""`tfloc export RUN --tum DIR`: TUM files that evo's own file interface reads back with the
same poses, timestamps from the dataset's stamps (or scan index), and evo's APE on them equal
to the position errors computed from estimates.csv."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from _paths import ROOT

from tfloc.cli import main
from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose, angdiff
from tfloc.errors import DatasetError, LogFormatError, ResultsError
from tfloc.harness.export import export_tum
from tfloc.io.scenario import Scan, read_scans, read_scenario, write_scenario
from tfloc.io.tum import read_tum, write_tum

file_interface = pytest.importorskip("evo.tools.file_interface")
COLS = ["dataset", "scan_id", "group", "matcher", "true_x", "true_y", "true_theta", "init_x", "init_y",
        "init_theta", "est_x", "est_y", "est_theta", "status", "runtime_s"]


def _evo_planar(path: Path) -> tuple[np.ndarray, np.ndarray]:
    traj = file_interface.read_tum_trajectory_file(str(path))
    w, x, y, z = traj.orientations_quat_wxyz.T
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    assert np.allclose(traj.positions_xyz[:, 2], 0) and np.allclose(x, 0) and np.allclose(y, 0)
    return traj.timestamps, np.column_stack((traj.positions_xyz[:, :2], yaw))


def test_write_tum_reads_back_in_evo_and_here(tmp_path) -> None:
    rng = np.random.default_rng(3)
    t = 1_700_000_000.0 + np.cumsum(rng.uniform(0.05, 0.2, 50))
    P = np.column_stack((rng.uniform(-50, 50, (50, 2)), rng.uniform(-math.pi, math.pi, 50)))
    path = write_tum(tmp_path / "a.tum", t, P)
    for tt, pp in (_evo_planar(path), read_tum(path)):
        np.testing.assert_allclose(tt, t, atol=1e-6)
        np.testing.assert_allclose(pp[:, :2], P[:, :2], atol=1e-8)
        np.testing.assert_allclose(angdiff(pp[:, 2], P[:, 2]), 0, atol=1e-10)


def test_read_tum_rejects_bad_lines(tmp_path) -> None:
    (tmp_path / "b.tum").write_text("# header\n1 2 3 0 0 0 0 1\n2 2 3 0 0 0 1\n")
    with pytest.raises(LogFormatError, match=r"b.tum:3: expected 8 fields"):
        read_tum(tmp_path / "b.tum")
    (tmp_path / "c.tum").write_text("1 2 3 0 0 0 0 0\n")
    with pytest.raises(LogFormatError, match=r"c.tum:1: non-finite value or zero quaternion"):
        read_tum(tmp_path / "c.tum")


def _dataset(root: Path, stamps: bool) -> list[Scan]:
    rng = np.random.default_rng(5)
    laser = LaserSpec.lms200()
    scans = [Scan(f"s{k:05d}", "d1-a1", np.full(laser.n_beams, 3.0),
                  Pose(*rng.uniform(0, 5, 2), rng.uniform(-3, 3)), Pose(*rng.uniform(0, 5, 2), rng.uniform(-3, 3)),
                  stamp=1_700_000_000.0 + 0.1 * k if stamps else None)
             for k in range(8)]
    write_scenario(root, root.name, ROOT / "data" / "maps" / "test-room.geojson", laser, scans)
    return scans


def _run(run_dir: Path, dataset: str, scans: list[Scan]) -> list[dict]:
    """An estimates.csv as the harness runner writes it: two matchers, one failing twice."""
    rng = np.random.default_rng(9)
    rows = []
    for m in ("tf", "o3d-icp"):
        for k, s in enumerate(reversed(scans)):  # not in time order
            est = s.true.as_array() + rng.normal(0, [0.05, 0.05, 0.01])
            if m == "o3d-icp" and k in (2, 5):
                est, status = ["", "", ""], "error:boom"
            else:
                status = "ok"
            rows.append(dict(zip(COLS, [dataset, s.scan_id, s.group, m, s.true.x, s.true.y, s.true.theta,
                                        s.initial.x, s.initial.y, s.initial.theta, *est, status, 0.01],
                                 strict=True)))
    run_dir.mkdir(parents=True)
    with (run_dir / "estimates.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, COLS)
        w.writeheader()
        w.writerows(rows)
    return rows


def test_export_run_to_tum_with_stamps(tmp_path, capsys) -> None:
    scans = _dataset(tmp_path / "scenarios" / "mybag", stamps=True)
    rows = _run(tmp_path / "results" / "run1", "mybag", scans)
    assert main(["export", str(tmp_path / "results" / "run1"), "--tum", str(tmp_path / "tum"),
                 "--datasets", str(tmp_path / "scenarios")]) == 0
    out = capsys.readouterr().out
    assert "mybag o3d-icp: 6 poses, 2 without a pose (times: stamp)" in out
    d = tmp_path / "tum" / "mybag"
    assert sorted(p.name for p in d.iterdir()) == ["initial.tum", "o3d-icp.tum", "reference.tum", "tf.tum"]
    t, P = _evo_planar(d / "reference.tum")
    np.testing.assert_allclose(t, [s.stamp for s in scans], atol=1e-6)
    np.testing.assert_allclose(P, [s.true.as_array() for s in scans], atol=1e-8)
    t, P = _evo_planar(d / "initial.tum")
    np.testing.assert_allclose(P, [s.initial.as_array() for s in scans], atol=1e-8)
    for m in ("tf", "o3d-icp"):
        mine = sorted((next(s.stamp for s in scans if s.scan_id == r["scan_id"]), r) for r in rows
                      if r["matcher"] == m and r["est_x"] != "")
        t, P = _evo_planar(d / f"{m}.tum")
        np.testing.assert_allclose(t, [a for a, _ in mine], atol=1e-6)
        np.testing.assert_allclose(P[:, :2], [[r["est_x"], r["est_y"]] for _, r in mine], atol=1e-8)
        np.testing.assert_allclose(angdiff(P[:, 2], [r["est_theta"] for _, r in mine]), 0, atol=1e-10)


def test_evo_ape_on_exported_files_equals_our_errors(tmp_path) -> None:
    from evo.core import metrics, sync

    scans = _dataset(tmp_path / "scenarios" / "mybag", stamps=True)
    rows = _run(tmp_path / "run", "mybag", scans)
    export_tum(tmp_path / "run", tmp_path / "tum", tmp_path / "scenarios")
    ref = file_interface.read_tum_trajectory_file(str(tmp_path / "tum" / "mybag" / "reference.tum"))
    est = file_interface.read_tum_trajectory_file(str(tmp_path / "tum" / "mybag" / "o3d-icp.tum"))
    ref, est = sync.associate_trajectories(ref, est)
    ape = metrics.APE(metrics.PoseRelation.translation_part)
    ape.process_data((ref, est))
    ours = [math.hypot(float(r["est_x"]) - float(r["true_x"]), float(r["est_y"]) - float(r["true_y"]))
            for r in rows if r["matcher"] == "o3d-icp" and r["est_x"] != ""]
    assert ape.get_statistic(metrics.StatisticsType.rmse) == pytest.approx(np.sqrt(np.mean(np.square(ours))),
                                                                           rel=1e-9)


def test_export_without_stamps_uses_scan_index(tmp_path) -> None:
    scans = _dataset(tmp_path / "scenarios" / "gen", stamps=False)
    assert read_scans(read_scenario(tmp_path / "scenarios" / "gen"))[0].stamp is None
    _run(tmp_path / "run", "gen", scans)
    done = export_tum(tmp_path / "run", tmp_path / "tum", tmp_path / "scenarios")
    assert {e.stamps for e in done} == {"index"}
    t, _ = _evo_planar(tmp_path / "tum" / "gen" / "reference.tum")
    np.testing.assert_array_equal(t, np.arange(8.0))
    # the dataset cannot be found: the order of first appearance in the run
    done = export_tum(tmp_path / "run", tmp_path / "tum2", tmp_path / "nowhere")
    assert {e.stamps for e in done} == {"run order"}
    t, P = read_tum(tmp_path / "tum2" / "gen" / "reference.tum")
    np.testing.assert_array_equal(t, np.arange(8.0))
    np.testing.assert_allclose(P[0], scans[-1].true.as_array(), atol=1e-8)  # the run lists them reversed


def test_dataset_named_by_path(tmp_path, monkeypatch) -> None:
    """A run may name its datasets by path (as in benchmarks/*.toml): found there, files under
    the directory's name."""
    scans = _dataset(tmp_path / "data" / "scenarios" / "mybag", stamps=True)
    monkeypatch.chdir(tmp_path)
    _run(tmp_path / "run", "data/scenarios/mybag", scans)
    done = export_tum(tmp_path / "run", tmp_path / "tum", None)
    assert {e.stamps for e in done} == {"stamp"}
    t, _ = read_tum(tmp_path / "tum" / "mybag" / "reference.tum")
    np.testing.assert_allclose(t, [s.stamp for s in scans], atol=1e-6)


def test_export_errors(tmp_path) -> None:
    with pytest.raises(ResultsError, match="no such results file"):
        export_tum(tmp_path / "none", tmp_path / "tum")
    (tmp_path / "r").mkdir()
    (tmp_path / "r" / "estimates.csv").write_text("dataset,scan_id,matcher\nx,s1,tf\n")
    with pytest.raises(ResultsError, match=r"estimates.csv:1: header lacks column\(s\) true_x"):
        export_tum(tmp_path / "r", tmp_path / "tum")
    scans = _dataset(tmp_path / "scenarios" / "ds", stamps=True)
    rows = _run(tmp_path / "r3", "ds", scans)
    rows[0]["scan_id"] = "unknown"
    with (tmp_path / "r3" / "estimates.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, COLS)
        w.writeheader()
        w.writerows(rows)
    with pytest.raises(DatasetError, match=r"scan 'unknown' of dataset 'ds' is not in"):
        export_tum(tmp_path / "r3", tmp_path / "tum", tmp_path / "scenarios")
