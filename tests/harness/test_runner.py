"""The runner: error and timeout rows, resume after SIGKILL, outcome classification, bad data."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from _paths import ROOT

from tfloc.core.pose import Pose
from tfloc.errors import DatasetError
from tfloc.harness.config import MatcherSpec, RunConfig
from tfloc.harness.runner import run
from tfloc.io.estimates import read_estimates
from tfloc.io.scenario import Scan, write_scenario

ROOM = ROOT / "data" / "maps" / "test-room.geojson"
TESTS = Path(__file__).resolve().parents[1]


def make_dataset(root: Path, m, laser, n: int = 6, offset=(0.2, -0.1)) -> Path:
    """``n`` scans in the test room; initial = true − offset (so true = initial + offset)."""
    scans = []
    for i in range(n):
        true = Pose(3.0 + 0.3 * (i % 3), 3.5 + 0.4 * (i // 3), 0.1 * i)
        init = Pose(true.x - offset[0], true.y - offset[1], true.theta)
        scans.append(Scan(f"s{i}", f"g{i % 2}", m.raycast(true, laser), init, true))
    return write_scenario(root, root.name, ROOM, laser, scans)


def cfg(ds: Path, out: Path, *specs: MatcherSpec, **kw) -> RunConfig:
    return RunConfig(name="t", out=out, datasets=(ds,), matchers=specs, **kw)


def test_raising_and_hanging_matchers_leave_a_complete_run(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200)
    out = run(cfg(ds, tmp_path / "run", MatcherSpec.make("toy_matchers:Raises", label="raises"),
                  MatcherSpec.make("toy_matchers:Hangs", {"hang_every": 3}, label="hangs"),
                  MatcherSpec.make("toy_matchers:Stay", label="stay"),
                  jobs=2, timeout_s=3.0), progress=False)
    df = read_estimates(out)
    assert len(df) == 18 and not df.duplicated(["dataset", "scan_id", "matcher"]).any()
    assert df[df.matcher == "raises"].status.str.startswith("error:ValueError: toy failure").any()
    assert (df[df.matcher == "hangs"].status == "timeout").any()
    assert (df[df.matcher == "stay"].status == "ok").all()
    bad = df[df.status != "ok"]
    assert (bad.outcome == "no-answer").all() and bad.status.str.contains("\n").sum() == 0


@pytest.mark.parametrize("false_value, outcome", [(0.5, "local-optimum"), (-0.1, "ambiguous")])
def test_outcome_is_decided_by_the_matchers_own_objective(tmp_path, test_room, lms200,
                                                           false_value, outcome):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2)
    spec = MatcherSpec.make("toy_matchers:TwoMinima", {"to_true": [0.2, -0.1], "to_false": [1.0, 0.5],
                                                       "false_value": false_value}, label="toy")
    df = read_estimates(run(cfg(ds, tmp_path / "run", spec, jobs=1), progress=False))
    assert (df.outcome == outcome).all()
    assert (df.score_true < df.score_est).all() == (outcome == "local-optimum")


def test_success_outcome(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2, offset=(0.05, 0.0))
    df = read_estimates(run(cfg(ds, tmp_path / "run", MatcherSpec.make("toy_matchers:Stay", label="stay"),
                                jobs=1), progress=False))
    assert (df.outcome == "success").all() and df.dist_err_m.round(6).eq(0.05).all()


def test_malformed_row_is_rejected_with_file_and_line(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=3)
    lines = (ds / "scans.csv").read_text().splitlines()
    lines[2] = lines[2].rsplit(" ", 3)[0]
    (ds / "scans.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(DatasetError, match=r"scans\.csv:3: 178 ranges, expected 181"):
        run(cfg(ds, tmp_path / "run", MatcherSpec.make("toy_matchers:Stay")), progress=False)
    r = subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", str(ds), "--out",
                        str(tmp_path / "r2"), "--matchers", "tf"], capture_output=True, text=True)
    assert r.returncode == 2 and "scans.csv:3:" in r.stderr and "Traceback" not in r.stderr


def test_run_json_records_config_versions_and_machine(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=1)
    out = run(cfg(ds, tmp_path / "run", MatcherSpec.make("toy_matchers:Stay", label="stay"), jobs=1),
              progress=False)
    doc = json.loads((out / "run.json").read_text())
    assert doc["config"]["matchers"][0]["label"] == "stay"
    assert doc["versions"]["numpy"] and doc["machine"]["cpu_count"] >= 1
    assert doc["datasets"] == {"ds": str(ds)}
    assert isinstance(pd.read_csv(out / "estimates.csv"), pd.DataFrame)


def test_regenerate_reruns_a_complete_run_and_resumes_an_incomplete_one(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2)
    c = cfg(ds, tmp_path / "run", MatcherSpec.make("toy_matchers:Stay", label="stay"), jobs=1)
    est = run(c, progress=False) / "estimates.csv"
    lines = est.read_text().splitlines()
    est.write_text("\n".join(lines[:-1]) + "\n")                 # interrupted: one row missing
    run(c, progress=False, regenerate=True)
    df = read_estimates(tmp_path / "run")
    assert len(df) == 2
    first = json.loads((tmp_path / "run" / "run.json").read_text())["sessions"]
    assert len(first) == 2                                       # resumed, not restarted
    run(c, progress=False, regenerate=True)                      # complete: start over
    assert len(json.loads((tmp_path / "run" / "run.json").read_text())["sessions"]) == 1
    assert len(read_estimates(tmp_path / "run")) == 2


def test_a_warm_up_longer_than_the_task_limit_does_not_turn_tasks_into_timeouts(tmp_path, test_room, lms200):
    """The warm-up (kernels compiled before the timed tasks) has its own, longer limit: with the
    task's 1 s, a 2 s cold start would be killed and the worker's first task time out instead."""
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=3)
    out = run(cfg(ds, tmp_path / "run", MatcherSpec.make("toy_matchers:ColdStart", label="cold"),
                  jobs=1, timeout_s=1.0), progress=False)
    assert (read_estimates(out).status == "ok").all()


def test_a_run_of_another_configuration_without_rows_leaves_no_sessions_behind(tmp_path, test_room, lms200):
    """Per-scan rows are not always kept (the native runs' estimates are not committed): a run
    of another configuration into that directory starts a fresh record, not a 'resumed' one."""
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2)
    out = tmp_path / "run"
    run(cfg(ds, out, MatcherSpec.make("toy_matchers:Stay", label="stay"), jobs=1), progress=False)
    (out / "estimates.csv").unlink()
    run(cfg(ds, out, MatcherSpec.make("toy_matchers:Stay", label="other"), jobs=1), progress=False, regenerate=True)
    sessions = json.loads((out / "run.json").read_text())["sessions"]
    assert len(sessions) == 1 and set(read_estimates(out).matcher) == {"other"}
