"""tfloc bench on sequence datasets: one task per (sequence, matcher) writing one row per scan,
scored by the one outcome rule; a sequence cut off by a kill is dropped and run again on resume;
a tracker with no single-scan mode is left out of single-scan datasets with one line."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path

from _paths import ROOT

from tfloc.harness.config import MatcherSpec, RunConfig
from tfloc.harness.runner import make_tasks, run
from tfloc.io.estimates import read_estimates


def _short_sequence(dst: Path, n: int = 12) -> Path:
    src = ROOT / "data" / "scenarios" / "seq-quick"
    dst.mkdir(parents=True)
    text = (src / "scenario.json").read_text().replace('"../../maps/', f'"{ROOT}/data/maps/')
    (dst / "scenario.json").write_text(text)
    with (src / "scans.csv").open() as fh:
        lines = fh.readlines()
    (dst / "scans.csv").write_text("".join(lines[: n + 1]))
    return dst


def _config(tmp_path: Path, seq: Path, matchers=("tf-plus", "odometry")) -> RunConfig:
    return RunConfig("seq", tmp_path / "run", (seq,), tuple(MatcherSpec.make(m) for m in matchers), jobs=1)


def test_a_sequence_task_writes_one_scored_row_per_scan(tmp_path):
    seq = _short_sequence(tmp_path / "seq")
    cfg = _config(tmp_path, seq)
    tasks = make_tasks(cfg)
    assert len(tasks) == 2 and all(t.sequence and t.scan_id == "k0011" or t.sequence for t in tasks)
    out = run(cfg, progress=False)
    df = read_estimates(out)
    assert len(df) == 2 * 12
    tfp = df[df["matcher"] == "tf-plus"]
    assert list(tfp["scan_id"]) == sorted(tfp["scan_id"])  # in time order
    assert (tfp["outcome"] == "success").all() and tfp["dist_err_m"].max() < 0.05
    odo = df[df["matcher"] == "odometry"]
    assert odo["init_dist_err_m"].notna().all() and (odo["status"] == "ok").all()


def test_a_cut_sequence_is_run_again(tmp_path):
    seq = _short_sequence(tmp_path / "seq")
    cfg = _config(tmp_path, seq, ("tf-plus",))
    out = run(cfg, progress=False)
    est = out / "estimates.csv"
    full = est.read_text().splitlines()
    est.write_text("\n".join(full[:6]) + "\n")  # a kill after 5 of 12 rows
    run(cfg, progress=False)
    with est.open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 12 and len({r["scan_id"] for r in rows}) == 12


def test_a_tracker_is_left_out_of_single_scan_datasets(tmp_path, monkeypatch):
    from tfloc.harness import runner

    seq = _short_sequence(tmp_path / "seq")
    single = tmp_path / "single"
    shutil.copytree(ROOT / "data" / "scenarios" / "detail-1", single)
    text = (single / "scenario.json").read_text().replace('"../../maps/', f'"{ROOT}/data/maps/')
    (single / "scenario.json").write_text(text)
    monkeypatch.setattr(runner, "tracker_only", lambda spec: spec.label == "odometry")
    lines = []
    cfg = RunConfig("mix", tmp_path / "run", (single, seq),
                    (MatcherSpec.make("tf-plus"), MatcherSpec.make("odometry")), limit_per_group=1)
    tasks = make_tasks(cfg, lines.append)
    assert {t.label for t in tasks if not t.sequence} == {"tf-plus"}
    assert {t.label for t in tasks if t.sequence} == {"tf-plus", "odometry"}
    assert len(lines) == 1 and "odometry left out" in lines[0]
