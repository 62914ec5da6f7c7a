"""A run is one configuration (issue 13): bad parameters fail before the run, a run directory is
resumed only by the same configuration, error rows can be retried and set the exit status, tasks
the data cannot pose are `invalid`, matchers named `module:Class` need --allow-import, and an
output that cannot be written stops the run with one line and keeps what was written."""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from _paths import ROOT
from test_runner import make_dataset

from tfloc.core.pose import Pose
from tfloc.errors import ConfigError, ResultsError
from tfloc.harness.config import MatcherSpec, RunConfig
from tfloc.harness.runner import run
from tfloc.io import estimates as E
from tfloc.io.estimates import read_estimates
from tfloc.io.scenario import Scan, read_scans, read_scenario, write_scenario

TESTS = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), str(ROOT)])}
KEY = ["dataset", "scan_id", "matcher"]


def bench(*args, env=None) -> subprocess.CompletedProcess:
    """``tfloc bench ARGS`` in one worker process unless ARGS say otherwise (what these tests check
    does not depend on the pool's size; a second worker costs its start-up, seconds of CPU)."""
    jobs = [] if "--jobs" in map(str, args) else ["--jobs", "1"]
    return subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", *map(str, args), *jobs, "--no-progress"],
                          cwd=ROOT, env=env or ENV, capture_output=True, text=True, timeout=600)


def toml(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def one_line(r: subprocess.CompletedProcess) -> str:
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    return lines[0]


# --- 1. fail before the run -------------------------------------------------------------------

def test_a_misspelled_parameter_stops_the_run_before_anything_is_written(tmp_path):
    out = tmp_path / "run"
    cfg = toml(tmp_path / "c.toml", f'''datasets = ["data/scenarios/detail-1"]
matchers = ["csm-corr"]
out = "{out}"
limit_per_group = 1
[params.csm-corr]
search_radiuss = 2.0
''')
    r = bench(cfg)
    line = one_line(r)
    assert r.returncode == 2 and not out.exists()
    assert f"{cfg}: [params.csm-corr] search_radiuss: matcher 'csm-corr': unknown parameter(s) search_radiuss" in line
    assert "known: block, expand_batch, min_mean_likelihood, refine_max_evals" in line


@pytest.mark.parametrize("body, key", [
    ('matchers = [{ label = "fine", name = "csm-corr", params = { sigma = -0.1 } }]',
     "matchers[0].params.sigma: matcher 'csm-corr': sigma must be > 0, got -0.1"),
    ('[[sweep]]\nname = "tf"\ngrid = { spacing = [0.5, 0.0] }',
     "sweep[0].grid.spacing (point tf[spacing=0.0]): matcher 'tf': spacing must be > 0"),
    ('matchers = ["tf-plus"]\n[params.tf-plus]\nrefinement = { iterations = "six" }',
     "[params.tf-plus] refinement: matcher 'tf-plus': refinement.iterations must be an integer, got 'six'"),
])
def test_a_bad_value_is_named_by_its_configuration_key(tmp_path, body, key):
    out = tmp_path / "run"
    cfg = toml(tmp_path / "c.toml", f'datasets = ["data/scenarios/detail-1"]\nout = "{out}"\n{body}\n')
    r = bench(cfg)
    assert r.returncode == 2 and key in one_line(r) and not out.exists()


def test_localize_builds_its_matcher_before_opening_the_output(tmp_path):
    def localize(*extra):
        return subprocess.run([sys.executable, "-m", "tfloc.cli", "localize", "--dataset", "data/scenarios/detail-1",
                               "--out", str(tmp_path / "e.csv"), "--limit", "1", *extra],
                              cwd=ROOT, capture_output=True, text=True, timeout=300)

    r = localize("--matcher", "tf", "--param", "spacingg=0.5")
    assert r.returncode == 2 and not (tmp_path / "e.csv").exists()
    assert "--param spacingg: matcher 'tf': unknown parameter(s) spacingg; known: " in one_line(r)
    r = localize("--matcher", "tf-plus", "--param", "grid_step=-0.1")
    assert r.returncode == 2 and "--param grid_step: matcher 'tf-plus': grid_step must be > 0" in one_line(r)
    r = localize("--matcher", "tf-plus", "--param", "select=tf", "--param", "heading_offsets=[0.0]")
    assert r.returncode == 0 and pd.read_csv(tmp_path / "e.csv").status.tolist() == ["ok"], r.stderr


# --- 2. a run is one configuration ------------------------------------------------------------

def csm(tmp_path: Path, sigma: float) -> Path:
    return toml(tmp_path / "c.toml", f'''datasets = ["data/scenarios/detail-1"]
matchers = ["csm-corr"]
out = "{tmp_path / 'run'}"
limit_per_group = 1
[params.csm-corr]
sigma = {sigma}
''')


def test_a_finished_run_is_not_resumed_with_another_parameter(tmp_path):
    r = bench(csm(tmp_path, 0.1))
    assert r.returncode == 0, r.stderr
    assert "rows: 9 (ok 9, failed 0, invalid 0, timeout 0, error 0)" in r.stderr
    before = (tmp_path / "run" / "estimates.csv").read_bytes()
    fp = json.loads((tmp_path / "run" / "run.json").read_text())["fingerprint"]
    assert fp["matchers"]["csm-corr"]["params"]["sigma"] == 0.1 and fp["matchers"]["csm-corr"]["params"]["block"] == 8
    assert set(fp["datasets"]["detail-1"]) == {"scenario.json", "scans.csv", "map:office-1.geojson"}
    assert bench(csm(tmp_path, 0.1)).returncode == 0  # the same configuration: resumed (nothing to do)
    r = bench(csm(tmp_path, 0.2))
    line = one_line(r)
    assert r.returncode == 2 and "holds a run of another configuration: csm-corr: sigma 0.1 → 0.2" in line
    assert "--regenerate" in line and "another --out" in line
    assert (tmp_path / "run" / "estimates.csv").read_bytes() == before
    r = bench(csm(tmp_path, 0.2), "--regenerate")
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "run" / "run.json").read_text())
    assert doc["fingerprint"]["matchers"]["csm-corr"]["params"]["sigma"] == 0.2 and len(doc["sessions"]) == 1


def test_changed_data_thresholds_or_matchers_are_named(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2)
    spec = MatcherSpec.make("toy_matchers:TwoMinima", {"false_value": 0.5}, label="toy")
    c = RunConfig(name="t", out=tmp_path / "run", datasets=(ds,), matchers=(spec,), jobs=1)
    run(c, progress=False)
    scans = (ds / "scans.csv").read_bytes()
    (ds / "scans.csv").write_bytes(scans.replace(b"g0", b"g2"))
    with pytest.raises(ConfigError, match=r"dataset ds: scans.csv changed"):
        run(c, progress=False)
    (ds / "scans.csv").write_bytes(scans)
    from tfloc.core.thresholds import Thresholds
    with pytest.raises(ConfigError, match=r"success dist_m 0.1 → 0.05"):
        run(c.with_overrides(success=Thresholds(0.05, 2.0)), progress=False)
    other = MatcherSpec.make("toy_matchers:TwoMinima", {"false_value": 0.4}, label="toy")
    with pytest.raises(ConfigError, match=r"toy: false_value 0.5 → 0.4"):
        run(c.with_overrides(matchers=(other,)), progress=False)
    with pytest.raises(ConfigError, match=r"matcher stay added"):
        run(c.with_overrides(matchers=(spec, MatcherSpec.make("toy_matchers:Stay", label="stay"))), progress=False)
    run(c.with_overrides(timeout_s=5.0, jobs=2), progress=False)  # limits are not the configuration


def test_a_run_without_a_fingerprint_is_not_resumed(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2)
    c = RunConfig(name="t", out=tmp_path / "run", datasets=(ds,), jobs=1,
                  matchers=(MatcherSpec.make("toy_matchers:Stay", label="stay"),))
    run(c, progress=False)
    (tmp_path / "run" / "run.json").write_text("{")  # unreadable, as an older tfloc's partial write could be
    with pytest.raises(ConfigError, match="records no fingerprint"):
        run(c, progress=False)
    run(c, progress=False, regenerate=True)
    assert len(read_estimates(tmp_path / "run")) == 2


def test_damaged_results_are_refused_unless_regenerated(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2)
    c = RunConfig(name="t", out=tmp_path / "run", datasets=(ds,), jobs=1,
                  matchers=(MatcherSpec.make("toy_matchers:Stay", label="stay"),))
    est = run(c, progress=False) / "estimates.csv"
    est.write_text(est.read_text().replace("status", "state", 1))  # a header without 'status'
    with pytest.raises(ResultsError, match=r"estimates.csv:1: header lacks column\(s\) status"):
        run(c, progress=False)
    run(c, progress=False, regenerate=True)
    assert len(read_estimates(tmp_path / "run")) == 2


def test_retry_errors_reruns_error_rows_and_exit_3_until_then(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=4)
    args = [ds, "--out", tmp_path / "run", "--jobs", "1", "--allow-import",
            "--matchers", "toy_matchers:Flaky,toy_matchers:Stay"]
    r = bench(*args, env={**ENV, "TFLOC_TOY_FAIL": "1"})
    assert r.returncode == 3, r.stderr
    assert "rows: 8 (ok 4, failed 0, invalid 0, timeout 0, error 4)" in r.stderr and "--retry-errors" in r.stderr
    assert bench(*args).returncode == 3  # resumed: nothing to do, the error rows are still there
    r = bench(*args, "--retry-errors")
    assert r.returncode == 0 and "rows: 8 (ok 8," in r.stderr, r.stderr
    df = read_estimates(tmp_path / "run")
    assert len(df) == 8 and not df.duplicated(KEY).any() and (df.status == "ok").all()


def test_a_task_the_data_cannot_pose_is_invalid_not_an_error(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=3)
    scans = read_scans(read_scenario(ds))
    s = scans[1]
    scans[1] = Scan(s.scan_id, s.group, s.ranges, Pose(40.0, 3.0, 0.0), s.true)  # initial pose off the map
    write_scenario(ds, "ds", ROOT / "data" / "maps" / "test-room.geojson", lms200, scans)
    r = bench(ds, "--out", tmp_path / "run", "--jobs", "1", "--allow-import", "--matchers", "toy_matchers:Stay")
    assert r.returncode == 0 and "rows: 3 (ok 2, failed 0, invalid 1, timeout 0, error 0)" in r.stderr, r.stderr
    df = read_estimates(tmp_path / "run")
    bad = df[df.scan_id == "s1"].iloc[0]
    assert bad.status.startswith("invalid:") and "scans.csv:3: initial pose (40.000, 3.000) lies outside the map" in bad.status
    assert bad.outcome == "no-answer"
    from tfloc.cli.report import make_report as write_report
    from tfloc.evaluation.metrics import summarize

    m = summarize(df).iloc[0]
    assert m.n_invalid == 1 and m.n_error == 0 and m.n_no_answer == 1
    text = write_report(tmp_path / "run", with_figures=False).report.read_text()
    assert "## Tasks the data cannot pose (invalid)" in text and "1 × `initial pose (40.000, 3.000) lies outside" in text
    assert "invalid: 1" in text


# --- 6. module:Class matchers -----------------------------------------------------------------

def test_a_module_class_matcher_needs_allow_import(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=1)
    r = bench(ds, "--out", tmp_path / "run", "--matchers", "toy_matchers:Stay")
    line = one_line(r)
    assert r.returncode == 2 and not (tmp_path / "run").exists()
    assert "'toy_matchers:Stay' names a Python class" in line and "--allow-import" in line
    cfg = toml(tmp_path / "c.toml", f'datasets = ["{ds}"]\nout = "{tmp_path / "run"}"\n'
                                    'matchers = [{ label = "x", name = "toy_matchers:Stay" }]\n')
    r = bench(cfg)
    assert r.returncode == 2 and f"{cfg}: matchers[0]: 'toy_matchers:Stay' names a Python class" in one_line(r)
    assert bench(cfg, "--allow-import").returncode == 0
    help_text = subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", "--help"], capture_output=True,
                               text=True, cwd=ROOT).stdout
    assert "--allow-import" in help_text and "runs the module's" in help_text and "Exit status" in help_text


# --- 5. an output that cannot be written ------------------------------------------------------

class FailingFile:
    """A results file whose writes fail with ``error`` after ``room`` more characters: a write past
    it writes what fits, then raises (a full disk: ENOSPC; a directory made read-only: EACCES)."""

    def __init__(self, fh, room: int, error: int) -> None:
        self.fh, self.room, self.error = fh, room, error

    def write(self, text: str) -> int:
        if len(text) > self.room:
            self.fh.write(text[:self.room])
            self.fh.flush()
            self.room = 0
            raise OSError(self.error, os.strerror(self.error))
        self.room -= len(text)
        return self.fh.write(text)

    def __getattr__(self, name):
        return getattr(self.fh, name)


@pytest.mark.parametrize("error", [errno.ENOSPC, errno.EACCES])
def test_an_output_that_cannot_be_written_stops_with_one_line_and_keeps_the_rows(tmp_path, test_room, lms200,
                                                                                 monkeypatch, error):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=12)
    c = RunConfig(name="t", out=tmp_path / "run", datasets=(ds,), jobs=1,
                  matchers=(MatcherSpec.make("toy_matchers:Stay", label="stay"),))
    opened = E.ResultWriter.__init__

    def failing(self, path):
        opened(self, path)  # the header is written; then a few rows fit (ENOSPC) or none (EACCES)
        self._fh = FailingFile(self._fh, 1500 if error == errno.ENOSPC else 0, error)
        self._w = E.csv.DictWriter(self._fh, fieldnames=E.COLUMNS, extrasaction="ignore")

    monkeypatch.setattr(E.ResultWriter, "__init__", failing)
    with pytest.raises(ResultsError) as err:
        run(c, progress=False)
    msg = str(err.value)
    assert "\n" not in msg and "estimates.csv: cannot write" in msg and "rows written before are kept" in msg
    assert ("disk is full" if error == errno.ENOSPC else "Permission denied") in msg
    kept = read_estimates(tmp_path / "run")  # a torn last line is dropped on reading, the rest is intact
    assert (len(kept) > 0) == (error == errno.ENOSPC) and (kept.status == "ok").all()
    monkeypatch.undo()
    df = read_estimates(run(c, progress=False))  # resumed once there is room again
    assert len(df) == 12 and not df.duplicated(KEY).any()
    assert df.set_index("scan_id").loc[kept.scan_id, "est_x"].tolist() == kept.est_x.tolist()


def test_an_output_directory_that_cannot_be_made_is_one_line(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=1)
    (tmp_path / "file").write_text("not a directory")
    r = bench(ds, "--out", tmp_path / "file" / "run", "--allow-import", "--matchers", "toy_matchers:Stay")
    assert r.returncode == 2 and "cannot create the run directory" in one_line(r)


# --- 3. one error type per kind of file -------------------------------------------------------

@pytest.mark.parametrize("damage, message", [
    (lambda lines: lines[:2] + [lines[2] + ",extra"] + lines[3:], rf"estimates.csv:3: {len(E.COLUMNS) + 1} fields, "
                                                                   rf"expected {len(E.COLUMNS)}"),
    (lambda lines: lines[:2] + [lines[1]] + lines[2:], r"estimates.csv:3: a second row for ds/s0/stay \(first at line 2\)"),
    (lambda lines: [lines[0]] + [lines[1].replace(",ok,", ",okay,")] + lines[2:], r"estimates.csv:2: unknown status 'okay'"),
])
def test_every_command_reads_a_damaged_estimates_csv_alike(tmp_path, test_room, lms200, damage, message):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=3)
    c = RunConfig(name="t", out=tmp_path / "run", datasets=(ds,), jobs=1,
                  matchers=(MatcherSpec.make("toy_matchers:Stay", label="stay"),))
    est = run(c, progress=False) / "estimates.csv"
    est.write_text("\n".join(damage(est.read_text().splitlines())) + "\n")
    from tfloc.cli.report import make_report as write_report
    from tfloc.harness.export import export_tum
    from tfloc.report.relations_note import write_note

    for command in (lambda: write_report(tmp_path / "run", with_figures=False),
                    lambda: export_tum(tmp_path / "run", tmp_path / "tum"),
                    lambda: write_note(tmp_path / "run", [ROOT / "data" / "scenarios" / "detail-1"]),
                    lambda: run(c, progress=False)):
        with pytest.raises(ResultsError, match=message):
            command()


def test_the_bag_importer_reports_argument_errors_as_one_type(tmp_path):
    from tfloc.datasets.from_bag import BagImport

    base = {"bag": tmp_path / "b.bag", "scan_topic": "/scan", "pose_topic": "/gt", "out": tmp_path / "o"}
    for bad in ({}, {"map_file": Path("m.yaml"), "map_topic": "/map"}, {"map_topic": "/map", "every": 0},
                {"map_topic": "/map", "initial_frames": ("a", "b")}, {"map_topic": "/map", "align_initial": True},
                {"map_topic": "/map", "max_pose_gap_s": 0.0}):
        with pytest.raises(ConfigError):
            BagImport(**base, **bad)
    r = subprocess.run([sys.executable, "-m", "tfloc.cli", "import-bag", str(tmp_path / "b.bag"), "--scan-topic",
                        "/scan", "--pose-topic", "/gt", "--map-topic", "/map", "--out", str(tmp_path / "o"),
                        "--every", "0"], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2 and "--every must be ≥ 1" in one_line(r)


# --- readers take what users have -------------------------------------------------------------

def test_a_spreadsheet_saved_scans_csv_localizes_and_benches(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2)
    text = (ds / "scans.csv").read_text()
    (ds / "scans.csv").write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    r = subprocess.run([sys.executable, "-m", "tfloc.cli", "localize", "--dataset", str(ds), "--matcher", "csm-corr",
                        "--out", str(tmp_path / "e.csv")], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert (pd.read_csv(tmp_path / "e.csv").status == "ok").all()
