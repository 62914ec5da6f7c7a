"""The bench runner: error/timeout rows, outcome classification, resume after SIGKILL, bad rows."""

import csv
import os
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from tfloc.cli import main
from tfloc.harness.config import RunConfig
from tfloc.harness.dataset import read_scans, read_scenario, write_scenario
from tfloc.harness.generate import BundleSpec, generate_bundle
from tfloc.harness.runner import run

ROOT = Path(__file__).resolve().parents[1]
TOY = "tests.toy_matchers"


@pytest.fixture(scope="module")
def bundle(tmp_path_factory):
    out = tmp_path_factory.mktemp("bundle")
    generate_bundle(out, BundleSpec(seed=11, pool_per_cell=1, detail_per_cell=1))
    return out


def _subset(bundle, dst, n):
    sc = read_scenario(bundle / "scenarios" / "detail-1")
    return write_scenario(dst, f"sub{n}", sc.map_path, sc.laser, read_scans(sc)[:n])


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_raising_and_hanging_matchers_leave_run_complete(bundle, tmp_path):
    ds = _subset(bundle, tmp_path / "ds", 2)
    cfg = RunConfig("t", str(tmp_path / "run"), (str(ds),),
                    (f"raise={TOY}:RaisingMatcher", f"hang={TOY}:HangingMatcher", f"id={TOY}:IdentityMatcher"),
                    jobs=2, timeout_s=3.0)
    rows = _rows(run(cfg, progress=False, log=lambda *_: None))
    by = {(r["matcher"], r["scan_id"]): r for r in rows}
    assert len(rows) == len(by) == 6
    for sid in ("d1-a1-000", "d1-a2-000"):
        assert by[("raise", sid)]["status"] == "error:RuntimeError: boom second line"
        assert by[("hang", sid)]["status"] == "timeout"
        assert by[("raise", sid)]["outcome"] == by[("hang", sid)]["outcome"] == "no-answer"
        assert by[("id", sid)]["status"] == "ok"
    assert (tmp_path / "run" / "run.json").exists()


def test_outcome_classification_with_known_false_optimum(bundle, tmp_path):
    ds = _subset(bundle, tmp_path / "ds", 1)
    t = read_scans(read_scenario(ds))[0].true
    cfg = RunConfig("t", str(tmp_path / "run"), (str(ds),),
                    (f"deep={TOY}:FalseOptimumMatcher", f"shallow={TOY}:FalseOptimumMatcher"),
                    jobs=1, timeout_s=30.0,
                    params={"deep": {"tx": t.x, "ty": t.y, "deep": True},
                            "shallow": {"tx": t.x, "ty": t.y, "deep": False}})
    rows = {r["matcher"]: r for r in _rows(run(cfg, progress=False, log=lambda *_: None))}
    assert rows["deep"]["outcome"] == "ambiguous"
    assert rows["shallow"]["outcome"] == "local-optimum"
    assert float(rows["deep"]["dist_err_m"]) == pytest.approx(2.0, abs=1e-5)
    assert float(rows["shallow"]["score_true"]) == pytest.approx(0.0, abs=1e-9)


def test_resume_after_sigkill(bundle, tmp_path):
    ds = _subset(bundle, tmp_path / "ds", 9)
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "tfloc.cli", "bench", str(ds), "--out", str(out), "--jobs", "2",
           "--no-progress", "--matchers", f"a={TOY}:SlowMatcher,b={TOY}:SlowMatcher"]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    p = subprocess.Popen(cmd, cwd=ROOT, env=env, start_new_session=True,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    est = out / "estimates.csv"
    deadline = time.time() + 60
    while time.time() < deadline:
        if est.exists() and est.read_text().count("\n") >= 4:
            break
        time.sleep(0.05)
    os.killpg(p.pid, signal.SIGKILL)
    p.wait()
    n_before = est.read_text().count("\n") - 1
    assert 3 <= n_before < 18, "the run must be killed mid-way"
    subprocess.run(cmd, cwd=ROOT, env=env, check=True, capture_output=True, timeout=120)
    keys = Counter((r["dataset"], r["scan_id"], r["matcher"]) for r in _rows(est))
    assert len(keys) == 18 and set(keys.values()) == {1}


def test_malformed_row_is_rejected_with_file_and_line(bundle, tmp_path, capsys):
    ds = _subset(bundle, tmp_path / "ds", 3)
    lines = (ds / "scans.csv").read_text().splitlines()
    parts = lines[2].split(",")
    parts[-1] = parts[-1].replace(" ", " x", 1)  # a non-number in the ranges of line 3
    lines[2] = ",".join(parts)
    (ds / "scans.csv").write_text("\n".join(lines) + "\n")
    rc = main(["bench", str(ds), "--matchers", f"id={TOY}:IdentityMatcher", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert rc == 2
    assert f"{ds / 'scans.csv'}:3" in err and "not a number" in err
    assert not (tmp_path / "r" / "estimates.csv").exists()


def test_report_from_a_run(bundle, tmp_path):
    from tfloc.harness.report import write_report

    dss = [str(bundle / "scenarios" / n) for n in ("office-pool", "detail-1")]
    cfg = RunConfig("t", str(tmp_path / "run"), tuple(dss), (f"tf={TOY}:IdentityMatcher",),
                    jobs=1, timeout_s=30.0)
    run(cfg, progress=False, log=lambda *_: None)
    text = write_report(tmp_path / "run").read_text()
    assert "Table 2" in text and "(7.7878)" in text and "Table 4" in text
    for f in ("scenario_errors", "convergence_basin", "error_cdf", "runtime", "outcomes"):
        assert (tmp_path / "run" / "figures" / f"{f}.png").stat().st_size > 1000
    summary = (tmp_path / "run" / "summary.csv").read_text().splitlines()
    assert summary[0].startswith("matcher,scenario,group,n,")
    assert np.isclose(float(next(r for r in csv.DictReader(summary) if r["scenario"] == "all")["success_rate"]), 0.0)
