"""The external-localizer protocol (tfloc.core.external, tfloc.baselines._external) with a tiny real
external program (a Python script): the tracking loop's batch path, the child's CPU time, the
one-line errors, restarts on slices, the program's identity in the fingerprint."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pytest
from _paths import ROOT
from tfloc.baselines._external import (
    ExternalProgramError,
    ProgramMissingError,
    find_program,
    read_table,
    run_program,
)

from tfloc.core.external import CPU_EVEN, CPU_OWN_LOG, BatchAnswer, ExternalProgram, split_cpu
from tfloc.core.pose import Pose
from tfloc.evaluation.truthfree.reconverge import Restart
from tfloc.harness.fingerprint import differences
from tfloc.harness.restarts import restart_ends
from tfloc.harness.track import track
from tfloc.io.scenario import read_scans, read_scenario, write_scenario

QUICK = ROOT / "data" / "scenarios" / "seq-quick"

# The external program: reads the odometry poses and the start, burns CPU, writes the dead-reckoned
# poses (start ⊕ odometry increments) and its own per-scan times; MODE fail / short misbehaves.
PROGRAM = r'''
import math, sys, time
mode, inp, out = sys.argv[1:4]
rows = [list(map(float, l.split())) for l in open(inp)]
if mode == "fail":
    print("reading the configuration", file=sys.stderr)
    print("bad config line 3", file=sys.stderr)
    sys.exit(2)
sx, sy, st = rows[0]
odo = rows[1:]
t0 = time.process_time()
while time.process_time() - t0 < 0.2:
    pass
x, y, t = sx, sy, st
with open(out, "w") as f, open(out + ".times", "w") as g:
    for k, (ox, oy, ot) in enumerate(odo):
        if k:
            px, py, pt = odo[k - 1]
            dx, dy = ox - px, oy - py
            c, s = math.cos(-pt), math.sin(-pt)
            lx, ly, lt = c * dx - s * dy, s * dx + c * dy, ot - pt
            x, y, t = x + math.cos(t) * lx - math.sin(t) * ly, y + math.sin(t) * lx + math.cos(t) * ly, t + lt
        if mode == "short" and k >= 2:
            break
        f.write(f"{x!r} {y!r} {t!r}\n")
        g.write(f"{k + 1}\n")
'''


class FakeExternal:
    """The script above through the protocol."""

    name = "fake-external"
    kind = "tracker"

    def __init__(self, script: Path, mode: str = "ok") -> None:
        self.script, self.mode = script, mode
        self.program = ExternalProgram(sys.executable, "python3", sys.version.split()[0], "fake.ini", f"mode={mode}")

    def run_batch(self, map, laser, ranges, stamps, odometry, start):
        d = self.script.parent / f"run-{time.monotonic_ns()}"
        d.mkdir()
        np.savetxt(d / "in.txt", np.vstack([[start.x, start.y, start.theta], odometry]), fmt="%.17g")
        run = run_program([sys.executable, str(self.script), self.mode, "in.txt", "out.txt"], d, tag="fake")
        n = len(ranges)
        poses = read_table(d / "out.txt", n, 3, "poses")
        own = read_table(d / "out.txt.times", n, 1, "per-scan times")[:, 0]
        per_scan, how = split_cpu(run.cpu_s, n, own if self.mode == "own" else None)
        return BatchAnswer(poses, run.cpu_s, run.wall_s, per_scan, how)


@pytest.fixture
def setup(tmp_path):
    sc = read_scenario(QUICK)
    root = write_scenario(tmp_path / "q", "q", sc.map_path, sc.laser, read_scans(sc)[:8], mode="sequence")
    script = tmp_path / "fake_localizer.py"
    script.write_text(PROGRAM)
    sc = read_scenario(root)
    return sc, read_scans(sc), script


def _dead_reckoning(scans, start):
    out, pose = [], start
    for k, s in enumerate(scans):
        if k:
            pose = pose.compose(scans[k - 1].odom.between(s.odom))
        out.append(pose)
    return out


def test_batch_rows_are_the_programs_poses_and_its_child_cpu(setup):
    sc, scans, script = setup
    c0 = time.process_time()
    rows = track(sc, scans, FakeExternal(script))
    parent_cpu = time.process_time() - c0
    want = _dead_reckoning(scans, scans[0].initial)
    assert [r.status.ok for r in rows] == [True] * len(scans)
    for k, r in enumerate(rows):
        assert (r.est_x, r.est_y, r.est_theta) == pytest.approx((want[k].x, want[k].y, want[k].theta), abs=1e-9)
        pred = scans[0].initial if k == 0 else Pose(rows[k - 1].est_x, rows[k - 1].est_y, rows[k - 1].est_theta).compose(
            scans[k - 1].odom.between(scans[k].odom))
        assert (r.init_x, r.init_y) == pytest.approx((pred.x, pred.y), abs=1e-9)
        assert r.info["cpu_from"] == CPU_EVEN
    cpu = [r.cpu_s for r in rows]
    assert sum(cpu) >= 0.18 and max(cpu) == pytest.approx(min(cpu))  # the child burned 0.2 s, split evenly
    assert parent_cpu < sum(cpu) + 1.0  # (the parent's own time is not what the rows carry)


def test_cpu_split_by_the_programs_own_times(setup):
    sc, scans, script = setup
    rows = track(sc, scans, FakeExternal(script, "own"))
    cpu = np.array([r.cpu_s for r in rows])
    assert rows[0].info["cpu_from"] == CPU_OWN_LOG
    assert cpu / cpu[0] == pytest.approx(np.arange(1, len(rows) + 1))
    assert split_cpu(2.0, 2, np.array([np.nan, 1.0])) == (pytest.approx([1.0, 1.0]), CPU_EVEN)


def test_failing_program_is_one_line_with_its_last_stderr_line(setup):
    sc, scans, script = setup
    rows = track(sc, scans, FakeExternal(script, "fail"))
    msg = rows[0].status.message
    assert all(r.status.kind.value == "error" for r in rows)
    assert "bad config line 3" in str(rows[0].status) and "exit status 2" in str(rows[0].status)
    assert "\n" not in msg
    want = _dead_reckoning(scans, scans[0].initial)  # answers at the prediction: dead reckoning
    assert (rows[-1].est_x, rows[-1].est_y) == pytest.approx((want[-1].x, want[-1].y))


def test_missing_rows_are_one_line_naming_the_file(setup, tmp_path):
    sc, scans, script = setup
    with pytest.raises(ExternalProgramError, match=r"out.txt: poses: 2 rows of 3 values, expected 8 rows of 3"):
        FakeExternal(script, "short").run_batch(None, sc.laser, [s.ranges for s in scans], None,
                                                np.array([[s.odom.x, s.odom.y, s.odom.theta] for s in scans]),
                                                scans[0].initial)
    with pytest.raises(ExternalProgramError, match=r"nothing.txt: cannot read poses"):
        read_table(tmp_path / "nothing.txt", 3, 3, "poses")


def test_missing_program_names_the_package():
    with pytest.raises(ProgramMissingError, match=r"^tfloc-no-such-program not found on PATH \(Debian: apt-get install some-pkg\)$"):
        find_program("tfloc-no-such-program", "some-pkg")


def test_restarts_run_the_program_on_the_slice(setup):
    sc, scans, script = setup
    own = np.array([[s.initial.x, s.initial.y, s.initial.theta] if s.initial else [0, 0, 0] for s in scans])
    own[2] = (1.0, 2.0, 0.5)
    rs = [Restart(first=2, last=5, offset=Pose(0.3, 0.0, 0.1))]
    end = restart_ends(sc, scans, FakeExternal(script), own, rs, None)
    want = _dead_reckoning(scans[2:6], Pose(1.0, 2.0, 0.5).compose(Pose(0.3, 0.0, 0.1)))[-1]
    assert end[0] == pytest.approx([want.x, want.y, want.theta], abs=1e-9)


def test_program_identity_enters_the_fingerprint():
    a = ExternalProgram("pf-localization", "mrpt-apps", "2.5.8", "x.ini", "[A]\nk=1\n")
    b = ExternalProgram("pf-localization", "mrpt-apps", "2.5.8", "x.ini", "[A]\nk=2\n")
    assert a.identity()["config_sha256"] != b.identity()["config_sha256"]
    fp = lambda p: {"tfloc": {"source": "s", "version": "v"}, "datasets": {}, "success": {},  # noqa: E731
                    "matchers": {"m": {"name": "m", "params": {}, "code": "tfloc", "program": p.identity()}}}
    assert any("program.config_sha256" in d for d in differences(fp(a), fp(b)))
    assert differences(fp(a), fp(a)) == []
