"""Chaos: a run of 240 tasks killed with SIGKILL at random moments, resumed each time, ends with
exactly one row per task, equal to an uninterrupted run but for the timing columns.

Kills land anywhere: while the command starts (building matchers, writing run.json, spawning
workers), between rows and in the middle of writing one. After every kill the results must still
be readable (a torn last line is the only damage allowed; one is added after the first kill
that left rows) and run.json must parse, and the session after it must count the finished rows. ``make test``
runs a short version (3 kills, local pool); ``make chaos`` the long one (10 kills each for the
local pool and ``--scheduler local:2``).
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from _paths import ROOT

from tfloc.core.pose import Pose
from tfloc.io.estimates import read_estimates, read_rows, repair
from tfloc.io.scenario import Scan, write_scenario

TESTS = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), str(ROOT)])}
KEY = ["dataset", "scan_id", "matcher"]
N_SCANS = 120  # × 2 matchers = 240 tasks


def dataset(root: Path, room, laser) -> Path:
    """``N_SCANS`` scans on a grid in the open part of the test room."""
    scans = []
    for i in range(N_SCANS):
        true = Pose(3.0 + 0.15 * (i % 12), 2.2 + 0.15 * (i // 12), 0.05 * i)
        scans.append(Scan(f"s{i:03d}", f"g{i % 3}", room.raycast(true, laser),
                          Pose(true.x - 0.2, true.y + 0.1, true.theta), true))
    return write_scenario(root, root.name, ROOT / "data" / "maps" / "test-room.geojson", laser, scans)


def command(ds: Path, out: Path, scheduler: str | None) -> list[str]:
    return [sys.executable, "-m", "tfloc.cli", "bench", str(ds), "--out", str(out), "--no-progress",
            "--jobs", "2", "--allow-import", "--timeout", "60",
            "--matchers", "toy_matchers:Stay,toy_matchers:TwoMinima",
            *(["--scheduler", scheduler] if scheduler else [])]


def rows(est: Path) -> int:
    try:
        return est.read_bytes().count(b"\n") - 1
    except FileNotFoundError:
        return 0


def comparable(df: pd.DataFrame) -> pd.DataFrame:
    """The rows without their timing columns (runtime, CPU time), in key order."""
    timing = [c for c in df.columns if c.startswith(("runtime", "cpu"))]
    return df.drop(columns=timing).sort_values(KEY).reset_index(drop=True)


def kill_and_resume(tmp_path: Path, ds: Path, scheduler: str | None, kills: int, seed: int) -> pd.DataFrame:
    """Start the run, SIGKILL it (with its workers) at a random moment, check what is left, and
    again, ``kills`` times; then let it finish. Returns the final estimates."""
    rng = random.Random(seed)
    out = tmp_path / "run"
    est = out / "estimates.csv"
    done, torn = 0, False
    for _ in range(kills):
        before = rows(est)
        proc = subprocess.Popen(command(ds, out, scheduler), env=ENV, start_new_session=True,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        if rng.random() < 0.3:  # while it starts, or early in the run (at most 20 rows in)
            target, deadline = before + 20, time.time() + rng.uniform(0.0, 4.0)
        else:  # after some rows, in the middle of the writing
            target, deadline = before + rng.randint(1, 20), time.time() + 120
        while rows(est) < target and proc.poll() is None and time.time() < deadline:
            time.sleep(0.002)
        time.sleep(rng.uniform(0.0, 0.03))
        finished = proc.poll() is not None
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:  # it had finished, workers and all
            pass
        proc.wait()
        assert not finished or proc.returncode == 0, proc.stderr.read().decode()
        done += not finished
        if est.exists():  # readable, but for at most a torn last line; no task twice
            repair(est)
            _, got = read_rows(est)
            assert len({tuple(r[k] for k in KEY) for _, r in got}) == len(got)
            if not torn:  # and one torn last line for certain, as a kill mid-write leaves it
                with est.open("a") as fh:
                    fh.write("ds,s999,g0,toy_matchers:Stay,3.0,3.5")
                torn = True
        if (out / "run.json").exists():
            json.loads((out / "run.json").read_text())
    kept = rows(est)  # the finished rows the last session finds (a torn line has no newline)
    r = subprocess.run(command(ds, out, scheduler), env=ENV, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr
    assert done >= kills * 0.8, f"only {done} of {kills} kills hit a running command"
    sessions = json.loads((out / "run.json").read_text())["sessions"]
    assert len(sessions) >= 2 and sessions[-1]["already_done"] >= kept
    return read_estimates(out)


def check(tmp_path: Path, test_room, lms200, scheduler: str | None, kills: int, seed: int) -> None:
    ds = dataset(tmp_path / "ds", test_room, lms200)
    ref = subprocess.run(command(ds, tmp_path / "ref", None), env=ENV, capture_output=True, text=True, timeout=900)
    assert ref.returncode == 0, ref.stderr
    final = kill_and_resume(tmp_path, ds, scheduler, kills, seed)
    assert len(final) == 2 * N_SCANS and not final.duplicated(KEY).any()
    pd.testing.assert_frame_equal(comparable(final), comparable(read_estimates(tmp_path / "ref")))


def test_killed_three_times_equals_an_uninterrupted_run(tmp_path, test_room, lms200):
    check(tmp_path, test_room, lms200, None, kills=3, seed=13)


@pytest.mark.slow
def test_killed_ten_times_local_pool(tmp_path, test_room, lms200):
    check(tmp_path, test_room, lms200, None, kills=10, seed=1)


@pytest.mark.slow
def test_killed_ten_times_on_a_local_dask_cluster(tmp_path, test_room, lms200):
    pytest.importorskip("distributed")
    check(tmp_path, test_room, lms200, "local:2", kills=10, seed=2)
