"""CARMEN and relations readers on real lines of the bundled logs, and on corrupted copies of them."""

from __future__ import annotations

import gzip
import math
from pathlib import Path

import numpy as np
import pytest

from tfloc.errors import LogFormatError
from tfloc.io.carmen import read_carmen
from tfloc.io.relations import join_relations, read_relations

FIX = Path(__file__).parents[1] / "fixtures" / "real"
REAL = Path(__file__).resolve().parents[2] / "data" / "real"
INTEL_HEAD = FIX / "intel-head.log"          # first 187 lines of intel-corrected.log
CSAIL_HEAD = FIX / "mit-csail-head.clf"      # first 6 lines of mit-csail.clf (3 comments, 3 FLASER)
REL_HEAD = FIX / "mit-csail-head.relations"  # first 5 lines of mit-csail.relations


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines()


def _write(tmp_path: Path, lines: list[str], name: str = "x.log") -> Path:
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


def _first(lines: list[str], kind: str) -> int:
    return next(i for i, s in enumerate(lines) if s.split()[:1] == [kind])


def test_reads_real_intel_lines() -> None:
    log = read_carmen(INTEL_HEAD)
    assert [s.kind for s in log.lasers] == ["FLASER", "FLASER"]
    s = log.lasers[0]
    assert s.ranges.shape == (180,) and s.ranges[0] == pytest.approx(1.09)
    assert s.pose.x == pytest.approx(0.600266) and s.pose.theta == pytest.approx(-0.354665)
    assert s.odom == s.pose  # GMapping output: both fields hold the corrected pose
    assert s.host == "pippo" and s.timestamp == pytest.approx(32.9068)
    assert s.line == _first(_lines(INTEL_HEAD), "FLASER") + 1
    assert len(log.odometry) == 180 and log.odometry[0].pose.x == 0.0
    assert log.params == {"robot_frontlaser_offset": "0.0", "robot_rearlaser_offset": "0.0"}
    assert log.skipped == {"NEFF": 1}


def test_reads_real_csail_clf_lines() -> None:
    log = read_carmen(CSAIL_HEAD)
    assert len(log.lasers) == 3 and log.ranges().shape == (3, 361)
    s = log.lasers[0]
    assert s.ranges[0] == pytest.approx(1.40) and s.host == "b21" and s.line == 4
    assert s.timestamp > 1.1e9 and not log.odometry


def test_gzip_is_detected(tmp_path: Path) -> None:
    p = tmp_path / "head.clf.gz"
    p.write_bytes(gzip.compress(CSAIL_HEAD.read_bytes()))
    assert len(read_carmen(p).lasers) == 3


def _corrupt(tmp_path: Path, src: Path, kind: str, edit) -> tuple[Path, int]:
    lines = _lines(src)
    i = _first(lines, kind)
    lines[i] = edit(lines[i].split())
    return _write(tmp_path, lines), i + 1


@pytest.mark.parametrize("src", [INTEL_HEAD, CSAIL_HEAD])
@pytest.mark.parametrize("case, edit, message", [
    ("truncated", lambda t: " ".join(t[:len(t) // 2]), "truncated"),
    ("cut-before-stamps", lambda t: " ".join(t[:-3]), "truncated"),
    ("garbled-range", lambda t: " ".join(t[:5] + ["1.2.3"] + t[6:]), "range[3] is not a number: '1.2.3'"),
    ("garbled-pose", lambda t: " ".join(t[:-9] + ["x0.6"] + t[-8:]), "not a number: 'x0.6'"),
    ("nan-pose", lambda t: " ".join(t[:-9] + ["nan"] + t[-8:]), "not finite"),
    ("one-beam-too-many", lambda t: " ".join([t[0], str(int(t[1]) + 1)] + t[2:]), "wrong beam count"),
    ("one-beam-too-few", lambda t: " ".join([t[0], str(int(t[1]) - 1)] + t[2:]), "wrong beam count"),
    ("negative-range", lambda t: " ".join(t[:2] + ["-1.0"] + t[3:]), "negative range at beam 0"),
    ("fractional-count", lambda t: " ".join([t[0], "180.5"] + t[2:]), "not a non-negative integer"),
])
def test_corrupted_laser_line_names_the_line(tmp_path: Path, src: Path, case: str, edit, message: str) -> None:
    p, lineno = _corrupt(tmp_path, src, "FLASER", edit)
    with pytest.raises(LogFormatError) as exc:
        read_carmen(p)
    text = str(exc.value)
    assert text.startswith(f"{p}:{lineno}: FLASER:"), text
    assert message in text, text
    assert "\n" not in text


@pytest.mark.parametrize("edit, message", [
    (lambda t: " ".join(t[:4]), "truncated"),
    (lambda t: " ".join(t[:3] + ["0..1"] + t[4:]), "odom theta is not a number"),
    (lambda t: " ".join(t + ["extra"]), "extra field"),
])
def test_corrupted_odom_line(tmp_path: Path, edit, message: str) -> None:
    p, lineno = _corrupt(tmp_path, INTEL_HEAD, "ODOM", edit)
    with pytest.raises(LogFormatError, match=rf"^{p}:{lineno}: ODOM: .*{message}"):
        read_carmen(p)


def test_truncated_param_and_garbage_lines(tmp_path: Path) -> None:
    lines = _lines(INTEL_HEAD)
    lines[_first(lines, "PARAM")] = "PARAM robot_frontlaser_offset"
    with pytest.raises(LogFormatError, match=r":3: PARAM: line is truncated"):
        read_carmen(_write(tmp_path, lines))
    lines = _lines(CSAIL_HEAD)
    lines[4] = "1.40 1.39 1.39"  # a line that lost its message name
    with pytest.raises(LogFormatError, match=r":5: not a CARMEN message"):
        read_carmen(_write(tmp_path, lines))


def test_truncated_gzip_file(tmp_path: Path) -> None:
    p = tmp_path / "cut.clf.gz"
    p.write_bytes(gzip.compress(CSAIL_HEAD.read_bytes())[:-40])
    with pytest.raises(LogFormatError, match="cut.clf.gz: damaged gzip data"):
        read_carmen(p)


def test_log_without_scans_and_missing_file(tmp_path: Path) -> None:
    with pytest.raises(LogFormatError, match="no laser scans"):
        read_carmen(_write(tmp_path, [s for s in _lines(INTEL_HEAD) if not s.startswith("FLASER")]))
    with pytest.raises(LogFormatError, match="no such log file"):
        read_carmen(tmp_path / "absent.log")


def test_robotlaser1_line(tmp_path: Path) -> None:
    """ROBOTLASER1 in CARMEN's layout, built from the first real CSAIL scan (no bundled log has one)."""
    s = read_carmen(CSAIL_HEAD).lasers[0]
    r = " ".join(f"{v:.2f}" for v in s.ranges)
    line = (f"ROBOTLASER1 0 {-math.pi / 2:.6f} {math.pi:.6f} {math.radians(0.5):.6f} 81.9 0.01 0 361 {r} 0 "
            f"{s.pose.x} {s.pose.y} {s.pose.theta} {s.odom.x} {s.odom.y} {s.odom.theta} 0.1 0.0 0.5 0.3 0 "
            f"{s.timestamp:.6f} b21 {s.logger_timestamp:.6f}")
    log = read_carmen(_write(tmp_path, [line]))
    rl = log.lasers[0]
    assert rl.kind == "ROBOTLASER1" and rl.laser.max_range == pytest.approx(81.9) and s.laser is None
    assert rl.laser.fov == pytest.approx(math.pi, abs=1e-6)
    assert rl.laser.angle_min == pytest.approx(-math.pi / 2, abs=1e-6) and rl.laser.n_beams == len(rl.ranges)
    np.testing.assert_allclose(rl.ranges, s.ranges)
    assert rl.pose.x == pytest.approx(s.pose.x)
    with pytest.raises(LogFormatError, match=r":1: ROBOTLASER1: .*truncated"):
        read_carmen(_write(tmp_path, [line.rsplit(" ", 12)[0]]))


def test_full_bundled_logs() -> None:
    clf = read_carmen(REAL / "mit-csail" / "mit-csail.clf.gz")
    assert len(clf.lasers) == 1988 and clf.ranges().shape == (1988, 361)
    intel = read_carmen(REAL / "intel" / "intel-corrected.log.gz")
    assert len(intel.lasers) == 910 and len(intel.odometry) == 14541 and intel.skipped == {"NEFF": 910}
    csail = read_carmen(REAL / "mit-csail" / "csail-corrected.log.gz")
    assert len(csail.lasers) == 406 and len(csail.odometry) == 2394 and len(csail.params) == 119


# -- relations -------------------------------------------------------------------------------

def test_reads_real_relations() -> None:
    rels = read_relations(REL_HEAD)
    assert len(rels) == 5
    assert rels[0].t1 == pytest.approx(1134864645.90321) and rels[0].delta.x == pytest.approx(0.31293)
    assert rels[0].delta.theta == pytest.approx(0.24198) and rels[3].line == 4


@pytest.mark.parametrize("edit, message", [
    (lambda t: " ".join(t[:7]), "7 fields, expected 8"),
    (lambda t: " ".join(t + ["0"]), "9 fields, expected 8"),
    (lambda t: " ".join(t[:2] + ["0.3l293"] + t[3:]), "field dx is not a number: '0.3l293'"),
    (lambda t: " ".join(t[:7] + ["inf"]), "field dyaw is not finite"),
])
def test_corrupted_relation_names_the_line(tmp_path: Path, edit, message: str) -> None:
    lines = _lines(REL_HEAD)
    lines[2] = edit(lines[2].split())
    p = _write(tmp_path, lines, "x.relations")
    with pytest.raises(LogFormatError, match=rf"^{p}:3: {message}"):
        read_relations(p)


def test_all_relations_join_the_real_log() -> None:
    rels = read_relations(REAL / "mit-csail" / "mit-csail.relations")
    scans = read_carmen(REAL / "mit-csail" / "mit-csail.clf.gz").lasers
    idx = join_relations(rels, scans)
    assert len(rels) == 1172 and idx.shape == (1172, 2)
    t = np.array([s.timestamp for s in scans])
    assert np.abs(t[idx[:, 0]] - [r.t1 for r in rels]).max() < 1e-5


def test_relation_without_a_scan_names_its_line(tmp_path: Path) -> None:
    scans = read_carmen(CSAIL_HEAD).lasers
    p = _write(tmp_path, [f"{scans[0].timestamp:.5f} {scans[1].timestamp + 0.5:.5f} 0 0 0 0 0 0"], "r")
    with pytest.raises(LogFormatError, match=r":1: t2=.* matches no scan"):
        join_relations(read_relations(p), scans, p)
