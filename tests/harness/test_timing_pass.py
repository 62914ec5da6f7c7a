"""The side-by-side timing pass (tfloc timing RUN): the sample, the interleaving, the summary, its
record in run.json (already complete, timed again for another configuration or a changed run,
removed with the run) and the quick run's configuration."""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pytest
from _paths import ROOT

from tests._estimates import frame, row
from tests.harness.test_runner import cfg, make_dataset
from tfloc.cli import build_parser, main
from tfloc.cli.bench import QUICK_PER_GROUP, config_from_args
from tfloc.core.rows.timing import TimingRow
from tfloc.errors import ConfigError
from tfloc.evaluation.contention import MAX_NEIGHBOUR_CORES
from tfloc.evaluation.timing import reference_of, timing_summary
from tfloc.harness.config import MatcherSpec
from tfloc.harness.runner import run
from tfloc.harness.timing import run_timing, sample_scans
from tfloc.harness.timing_pass import timing_pass
from tfloc.report.timing import write_timing_md

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "tests"), str(ROOT)])}


def _estimates() -> pd.DataFrame:
    rows = []
    for d in ("d1", "d2"):
        for g in ("a", "b", "c"):
            for i in range(10):
                for m in ("x", "y"):
                    status = "timeout" if (d, g, i, m) == ("d1", "a", 0, "y") else "ok"
                    rows.append(row(m, dataset=d, group=g, scan_id=f"{g}{i}", status=status))
    return frame(rows)


def test_sample_is_stratified_seeded_and_skips_scans_without_an_answer():
    df = _estimates()
    s = sample_scans(df, 4, seed=1)
    assert len(s) == 2 * 3 * 4 and (s.groupby(["dataset", "group"]).size() == 4).all()
    big = sample_scans(df, 10, seed=1)  # d1/a has only 9 scans every matcher answered (a0 timed out)
    assert not ((big["dataset"] == "d1") & (big["scan_id"] == "a0")).any()
    assert len(big) == 59 and ((big["dataset"] == "d2") & (big["scan_id"] == "a0")).any()
    pd.testing.assert_frame_equal(s, sample_scans(df, 4, seed=1))
    assert not s.equals(sample_scans(df, 4, seed=2))
    with pytest.raises(ConfigError):
        sample_scans(df, 0)


def test_summary_ratios_and_the_runs_own_cpu_times():
    t = pd.DataFrame([{"dataset": "d", "scan_id": f"s{i}", "matcher": m, "cpu_ms": c * (i + 1),
                       "wall_ms": 2 * c * (i + 1)} for i in range(9) for m, c in (("ref", 2.0), ("m", 6.0))])
    run_rows = frame([row(m, dataset="d", scan_id=f"s{i}", runtime_s=1.0, cpu_s=c * (i + 1) / 1000.0 * 1.5)
                      for i in range(9) for m, c in (("ref", 2.0), ("m", 6.0))])
    s = timing_summary(t, "ref", run_rows).set_index("matcher")
    assert s.loc["m", "ratio_to_reference"] == pytest.approx(3.0)
    assert s.loc["m", "ratio_lo"] == pytest.approx(3.0) and s.loc["m", "ratio_hi"] == pytest.approx(3.0)
    assert s.loc["m", "cpu_median_ms"] == pytest.approx(30.0)
    assert s.loc["ref", "run_over_quiet"] == pytest.approx(1.5)
    assert reference_of(["a", "tf-plus"]) == "tf-plus" and reference_of(["a", "b"]) == "a"
    with pytest.raises(ValueError):
        reference_of(["a"], "b")


def _config(ds: Path, out: Path, *specs: MatcherSpec):
    specs = specs or (MatcherSpec.make("tf-plus"), MatcherSpec.make("o3d-icp"),
                      MatcherSpec.make("toy_matchers:Stay", label="stay"))
    return cfg(ds, out, *specs, jobs=1, timeout_s=60.0)


@pytest.fixture(scope="module")
def small_run(tmp_path_factory, test_room, lms200):
    tmp = tmp_path_factory.mktemp("timing")
    ds = make_dataset(tmp / "ds", test_room, lms200, n=6)
    return run(_config(ds, tmp / "run"), progress=False)


def test_timing_pass_interleaves_matchers_and_restores_the_affinity(small_run):
    before = os.sched_getaffinity(0)
    rows, info = run_timing(small_run, per_stratum=2, warmup=1)
    assert os.sched_getaffinity(0) == before
    assert all(isinstance(r, TimingRow) for r in rows)
    assert len(rows) == 2 * 2 * 3  # 2 groups × 2 scans × 3 matchers
    # the order rotates scan by scan: each matcher is first on a different scan
    first = [r.matcher for r in rows if r.position == 0]
    assert first == ["tf-plus", "o3d-icp", "stay", "tf-plus"]
    assert all(r.cpu_ms > 0 for r in rows) and info["scans"] == 4 and len(info["cores"]) == 1


def test_timing_cli_writes_csv_and_markdown_and_the_report_links_it(small_run):
    r = subprocess.run([sys.executable, "-m", "tfloc.cli", "timing", str(small_run), "--per-stratum", "1",
                        "--warmup", "1", "--reference", "o3d-icp", "--allow-contended"], cwd=ROOT, env=ENV, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    md = (small_run / "timing.md").read_text()
    assert "CPU ratio to `o3d-icp` [95 % CI]" in md and "run / quiet" in md
    assert len(pd.read_csv(small_run / "timing.csv")) == 2 * 3
    record = json.loads((small_run / "run.json").read_text())["timing"]
    assert record["complete"] and record["fingerprint"]["reference"] == "o3d-icp"
    assert len(record["sessions"]) == 1 and record["sessions"][0]["ended"] >= record["sessions"][0]["started"]
    from tfloc.cli.report import make_report as write_report

    assert "[timing.md](timing.md)" in write_report(small_run, with_figures=False).report.read_text()
    bad = subprocess.run([sys.executable, "-m", "tfloc.cli", "timing", str(small_run), "--reference", "nope"],
                         cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "reference matcher 'nope'" in bad.stderr


def _copy(small_run: Path, tmp_path: Path) -> Path:
    out = tmp_path / "run"
    shutil.copytree(small_run, out)
    return out


def _doc(run_dir: Path) -> dict:
    return json.loads((run_dir / "run.json").read_text())


def test_a_complete_timing_pass_is_not_timed_again(small_run, tmp_path, monkeypatch, capsys):
    run_dir = _copy(small_run, tmp_path)
    timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=lambda s: None)
    record = _doc(run_dir)["timing"]
    assert record["complete"] and record["fingerprint"]["run"] == _doc(run_dir)["fingerprint"]
    assert {k: record["fingerprint"][k] for k in ("per_stratum", "warmup", "reference")} == {
        "per_stratum": 1, "warmup": 1, "reference": "tf-plus"}
    before = {f: (run_dir / f).read_bytes() for f in ("timing.csv", "timing.md", "run.json")}

    def no_timing(*args, **kwargs):
        raise AssertionError("a current timing pass was timed again")

    monkeypatch.setattr("tfloc.harness.timing_pass.run_timing", no_timing)
    logged: list[str] = []
    assert timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=logged.append) == run_dir
    assert logged == [f"{run_dir}: already complete: timing.md is current (--regenerate times it again)"]
    assert main(["timing", str(run_dir), "--per-stratum", "1", "--warmup", "1", "--allow-contended"]) == 0
    assert "already complete: timing.md is current" in capsys.readouterr().err
    assert {f: (run_dir / f).read_bytes() for f in before} == before


def test_another_configuration_or_a_changed_run_is_timed_again(small_run, tmp_path):
    run_dir = _copy(small_run, tmp_path)
    timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=lambda s: None)
    logged: list[str] = []
    timing_pass(run_dir, 2, 1, allow_contended=True, draw=write_timing_md, log=logged.append)
    assert logged[0] == f"{run_dir}: timing again: per_stratum 1 → 2"
    assert len(pd.read_csv(run_dir / "timing.csv")) == 2 * 2 * 3 and "2 scan(s) per dataset" in (
        run_dir / "timing.md").read_text()
    record = _doc(run_dir)["timing"]
    assert record["fingerprint"]["per_stratum"] == 2 and len(record["sessions"]) == 1 and record["complete"]
    doc = _doc(run_dir)                       # the run made again under other thresholds
    doc["fingerprint"]["success"]["dist_m"] = 0.2
    (run_dir / "run.json").write_text(json.dumps(doc))
    logged.clear()
    timing_pass(run_dir, 2, 1, allow_contended=True, draw=write_timing_md, log=logged.append)
    assert logged[0] == f"{run_dir}: timing again: the run changed (success dist_m 0.1 → 0.2)"
    doc = _doc(run_dir)                       # a pass cut off before it finished
    doc["timing"]["complete"] = False
    (run_dir / "run.json").write_text(json.dumps(doc))
    logged.clear()
    timing_pass(run_dir, 2, 1, allow_contended=True, draw=write_timing_md, log=logged.append)
    assert logged[0] == f"{run_dir}: timing again: the last timing pass did not finish"
    logged.clear()
    timing_pass(run_dir, 2, 1, regenerate=True, allow_contended=True, draw=write_timing_md, log=logged.append)
    assert logged[0] == f"{run_dir}: timing again (--regenerate)"
    assert len(_doc(run_dir)["timing"]["sessions"]) == 1


def test_bench_keeps_a_current_timing_pass_and_regenerate_removes_it(small_run, tmp_path):
    run_dir = _copy(small_run, tmp_path)
    timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=lambda s: None)
    ds = Path(next(iter(_doc(run_dir)["datasets"].values())))
    run(_config(ds, run_dir), progress=False)      # complete: nothing runs, a session is recorded
    assert _doc(run_dir)["timing"]["complete"] and len(_doc(run_dir)["sessions"]) == 2
    logged: list[str] = []
    timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=logged.append)
    assert logged == [f"{run_dir}: already complete: timing.md is current (--regenerate times it again)"]
    run(_config(ds, run_dir, MatcherSpec.make("toy_matchers:Stay", label="stay")), progress=False, regenerate=True)
    assert not (run_dir / "timing.csv").exists() and not (run_dir / "timing.md").exists()
    assert "timing" not in _doc(run_dir)


def _bench_args(*extra: str) -> argparse.Namespace:
    return build_parser().parse_args(["bench", str(ROOT / "benchmarks" / "paper-protocol.toml"), *extra])


def test_quick_is_a_stratified_subset_into_its_own_directory():
    c = config_from_args(_bench_args("--quick"))
    assert c.limit_per_group == QUICK_PER_GROUP and c.out == Path("results/paper-protocol-quick")
    assert c.name == "paper-protocol-quick"
    c = config_from_args(_bench_args("--quick", "--limit-per-group", "5", "--out", "x"))
    assert c.limit_per_group == 5 and c.out == Path("x")


def test_make_quicks_runs_land_where_the_quick_site_reads_them():
    """make quick runs paper-protocol.toml and sequences-quick.toml with --quick; each run lands in
    a directory the site's --only-quick reads (a quick study keeps its name: not *-quick-quick)."""
    from tfloc.site.pages import load_pages

    read = {r.dir for page in load_pages(quick=True) for r in page.runs}
    for study, out in (("paper-protocol", "paper-protocol-quick"), ("sequences-quick", "sequences-quick")):
        c = config_from_args(build_parser().parse_args(
            ["bench", str(ROOT / "benchmarks" / f"{study}.toml"), "--quick"]))
        assert c.out == Path("results") / out and c.name == out and out in read


def test_timing_md_names_the_code_it_timed_against_the_runs():
    from tfloc.report.timing import _code_line

    same = {"git": {"commit": "a" * 40, "dirty": False}, "run_git": {"commit": "a" * 40, "dirty": False}}
    assert _code_line(same) == "- Code timed: `aaaaaaa`, the run's own."
    later = {"git": {"commit": "b" * 40, "dirty": True}, "run_git": {"commit": "a" * 40, "dirty": False}}
    line = _code_line(later)
    assert "`bbbbbbb` with uncommitted changes" in line and "made by `aaaaaaa`" in line
    assert _code_line({}) == "- Code timed: not recorded."
    assert "made by unknown" in _code_line({"git": {"commit": "c" * 40}, "run_git": {}})


def test_a_tracking_run_is_timed_step_by_step_side_by_side(tmp_path):
    """A sequence run's trackers step along the sequence's first scans in turn, each on its own
    answers: one row per (step, tracker), every position taken in turn, the run's own CPU beside."""
    from test_track import _copy

    from tfloc.harness.timing_pass import timing_pass

    ds = _copy(tmp_path / "q", 30)
    out = run(cfg(ds, tmp_path / "run", MatcherSpec.make("tf-plus-track"), MatcherSpec.make("odometry"),
                  jobs=1, timeout_s=60.0), progress=False)
    timing_pass(out, per_stratum=1, warmup=0, allow_contended=True, draw=write_timing_md, log=lambda s: None)
    rows = pd.read_csv(out / "timing.csv")
    assert len(rows) == 30 * 2 and set(rows["matcher"]) == {"tf-plus-track", "odometry"}
    assert rows["scan_id"].nunique() == 30
    assert all(sorted(g) == [0, 1] for _, g in rows.groupby("scan_id")["position"])
    first = rows[rows["position"] == 0]["matcher"].tolist()
    assert first[:4] == ["tf-plus-track", "odometry", "tf-plus-track", "odometry"]
    assert (rows.loc[rows["matcher"] == "tf-plus-track", "cpu_ms"] > 0).all()
    assert "tf-plus-track" in (out / "timing.md").read_text()


@contextlib.contextmanager
def _cpu_hog(core: int) -> Iterator[subprocess.Popen]:
    """A ``while 1: pass`` process pinned to ``core`` for the block."""
    hog = subprocess.Popen([sys.executable, "-c", "while 1: pass"])
    try:
        os.sched_setaffinity(hog.pid, {core})
        time.sleep(0.2)
        yield hog
    finally:
        hog.kill()
        hog.wait()


def _cpu_s(pid: int) -> float:
    """A process's user + system CPU seconds (/proc/PID/stat)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


@pytest.mark.skipif(not Path("/proc/stat").exists(), reason="needs Linux's /proc")
def test_the_probe_counts_a_cpu_hog_on_its_core_as_a_neighbour():
    """Valid on a machine already busy: whatever else runs, the neighbours' share must include the
    hog's own measured share, and the hog alone is over the threshold."""
    from tfloc.harness.contention import probe_alone
    from tfloc.harness.pinning import pinned

    core = sorted(os.sched_getaffinity(0))[-1]
    with pinned([core]), _cpu_hog(core) as hog:
        t0, h0 = time.perf_counter(), _cpu_s(hog.pid)
        c = probe_alone(1.5)
        hog_cores = (_cpu_s(hog.pid) - h0) / (time.perf_counter() - t0)
    assert hog_cores > MAX_NEIGHBOUR_CORES  # the hog ran beside the probe
    assert c.neighbour_cores >= 0.9 * hog_cores - 0.02, (c, hog_cores)
    assert c.contended and c.rounds > 20 and c.calib_min_ms > 0


@pytest.mark.skipif(not Path("/proc/stat").exists(), reason="needs Linux's /proc")
def test_a_pass_beside_a_cpu_hog_is_refused_or_kept_marked_contended(small_run, tmp_path, capsys):
    run_dir = _copy(small_run, tmp_path)
    for f in ("timing.md", "timing.csv"):  # the module's run may have been timed by an earlier test
        (run_dir / f).unlink(missing_ok=True)
    core = sorted(os.sched_getaffinity(0))[-1]
    with _cpu_hog(core):
        assert main(["timing", str(run_dir), "--per-stratum", "1", "--warmup", "0", "--cores", str(core),
                     "--retries", "1", "--wait", "0"]) == 2
        err = capsys.readouterr().err
        assert "timing again in 0 s (try 2 of 2)" in err
        assert err.strip().splitlines()[-1].startswith(f"tfloc timing: error: {run_dir}: contended on each of 2 tries (")
        assert not (run_dir / "timing.md").exists() and not _doc(run_dir)["timing"]["complete"]
        timing_pass(run_dir, 1, 0, cores=[core], allow_contended=True, draw=write_timing_md, log=lambda s: None)
    md = (run_dir / "timing.md").read_text()
    assert md.splitlines()[0].startswith("# Timing pass: t (contended (×") and "**This pass ran contended" in md
    record = _doc(run_dir)["timing"]
    assert record["complete"] and record["sessions"][-1]["contention"]["contended"] is True
    assert record["sessions"][-1]["contention"]["neighbour_cores"] > MAX_NEIGHBOUR_CORES
    from tfloc.site.collect import timing_mark

    assert timing_mark(run_dir).startswith("contended (×")


def test_a_pass_made_before_the_probe_reads_as_not_measured(small_run, tmp_path, monkeypatch):
    """An older record (no ``contention``) is read, said not measured, never a crash: timing.md,
    the report's line, the site's mark, --verify; a contended try is not retried when quiet."""
    from tfloc.cli.report import make_report as write_report
    from tfloc.harness.timing_pass import timed_quietly
    from tfloc.harness.timing_verify import verify_pass
    from tfloc.report.timing import timing_markdown
    from tfloc.site.collect import timing_mark

    run_dir = _copy(small_run, tmp_path)
    timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=lambda s: None)
    doc = _doc(run_dir)
    for s in doc["timing"]["sessions"]:
        s.pop("contention")
    (run_dir / "run.json").write_text(json.dumps(doc))
    assert timing_mark(run_dir) == ""
    report = write_report(run_dir, with_figures=False).report.read_text()
    assert "The timing pass's own contention was not measured" in report and "run / quiet ×" in report
    summary = timing_summary(pd.read_csv(run_dir / "timing.csv"), "tf-plus")
    info = {"per_stratum": 1, "strata": 2, "scans": 2, "seed": 1, "warmup": 1, "cores": [0]}
    assert "- Contention: contention not measured (made before the contention probe)." in timing_markdown(
        "r", summary, "tf-plus", info)
    logged: list[str] = []
    assert verify_pass(run_dir, tolerance=1e9, allow_contended=True, log=logged.append)
    assert "committed pass: contention not measured (made before the contention probe)" in logged
    quiet = {"contention": {"calib_min_ms": 5.0, "calib_median_ms": 5.0, "neighbour_cores": 0.0}}
    calls: list[int] = []
    assert timed_quietly(lambda: (calls.append(1) or [], quiet), logged.append, retries=3, wait_s=0)[1] is quiet
    assert calls == [1]


def test_verify_fails_where_a_committed_time_is_off_by_more_than_the_tolerance(small_run, tmp_path, capsys):
    run_dir = _copy(small_run, tmp_path)
    timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=lambda s: None)
    t = pd.read_csv(run_dir / "timing.csv")
    t.loc[t["matcher"] == "o3d-icp", "cpu_ms"] *= 1000.0
    t.to_csv(run_dir / "timing.csv", index=False)
    assert main(["timing", str(run_dir), "--verify", "--allow-contended"]) == 1
    out = capsys.readouterr().out
    bad = out.split("does NOT agree within ×1.3: ")[1].splitlines()[0].split(", ")
    assert "o3d-icp" in bad and "committed_ms" in out  # the others may disagree on a busy machine
    assert main(["timing", str(tmp_path / "nope"), "--verify"]) == 2


def test_verify_compares_only_passes_made_at_the_same_machine_speed(small_run, tmp_path):
    """The probe judges a pass against itself, so a machine slowed throughout reads quiet; --verify
    also compares the calibration's best round with the committed pass's and refuses a re-timing
    outside ×1.25 of it (with --allow-contended: compared, the machine ratio said)."""
    import math

    from tfloc.evaluation.contention import Contention
    from tfloc.harness.timing_pass import ContendedError
    from tfloc.harness.timing_verify import apart_from, machine_ratio, verify_pass

    then = Contention(4.0, 4.0, 4.4, 10, 0.0)
    assert machine_ratio(then, Contention(5.2, 5.2, 5.6, 10, 0.0)) == pytest.approx(1.3)
    assert math.isnan(machine_ratio(None, then))
    assert apart_from(then)(Contention(4.8, 4.8, 5.0, 10, 0.0)) is None
    assert apart_from(then)(Contention(3.3, 3.3, 3.5, 10, 0.0)) is None
    assert "×1.30 the committed pass's (5.20 ms against 4.00" in apart_from(then)(Contention(5.2, 5.2, 5.6, 10, 0.0))
    assert "×0.75" in apart_from(then)(Contention(3.0, 3.0, 3.1, 10, 0.0))

    run_dir = _copy(small_run, tmp_path)
    timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=lambda s: None)
    doc = _doc(run_dir)
    doc["timing"]["sessions"][-1]["contention"]["calib_min_ms"] /= 4.0  # the pass was made on a machine 4× faster
    (run_dir / "run.json").write_text(json.dumps(doc))
    with pytest.raises(ContendedError, match=r"contended on each of 1 tries \(.*the calibration's best round is ×"):
        verify_pass(run_dir, retries=0, log=lambda s: None)
    logged: list[str] = []
    assert verify_pass(run_dir, tolerance=1e9, allow_contended=True, log=logged.append)
    machine = next(s for s in logged if s.startswith("machine now / then: ×"))
    assert float(machine.split("×")[1].split()[0]) > 2 and "per_machine" in "\n".join(logged)


def test_the_cpu_models_compared_and_where_the_committed_one_is_read():
    from tfloc.core.run import Machine, RunRecord, Session, TimingRecord
    from tfloc.harness.timing_verify import committed_cpu, other_cpu

    assert other_cpu("AMD EPYC", "Intel Xeon") == (
        "timed on AMD EPYC, this is Intel Xeon: absolute CPU times are not comparable; "
        "comparing the matchers' ratios to one another, measured side by side")
    assert other_cpu("AMD  EPYC", " AMD EPYC") is None and other_cpu(None, "AMD EPYC") is None
    assert other_cpu("AMD EPYC", "") is None
    machine = Machine(cpu="AMD EPYC")
    record = TimingRecord(sessions=(Session(cpu="Intel Xeon"),))
    assert committed_cpu(RunRecord(machine=machine, timing=record)) == ("Intel Xeon", "the timing pass's record")
    assert committed_cpu(RunRecord(machine=machine, timing=TimingRecord(sessions=(Session(),)))) == (
        "AMD EPYC", "the run's machine.cpu: the timing record names none")
    assert committed_cpu(RunRecord()) == (None, "not recorded")


def _retimed_as(run_dir: Path, monkeypatch, factors: dict[str, float], calls: list[int]) -> None:
    """--verify's re-timing made the committed rows times ``factors`` (per matcher), quiet by its
    own probe, its calibration's best round ×4 the committed pass's (far outside ×1.25)."""
    from dataclasses import replace

    from tfloc.evaluation.contention import Contention
    from tfloc.io.table import read_rows
    from tfloc.io.tables import TIMING

    committed = read_rows(run_dir / "timing.csv", TIMING)
    quiet_far = Contention(16.0, 16.0, 16.8, 10, 0.0).to_record()

    def retimed(*args, **kwargs):
        calls.append(1)
        return [replace(r, cpu_ms=r.cpu_ms * factors[r.matcher]) for r in committed], {"contention": quiet_far}

    monkeypatch.setattr("tfloc.harness.timing_verify.run_timing", retimed)


def test_verify_on_another_cpu_model_compares_the_matchers_ratios_to_one_another(small_run, tmp_path,
                                                                                monkeypatch, capsys):
    """A pass committed on another CPU model: one line says so, the matchers' ratios to the
    reference are compared side by side (a uniform ×1.8 passes, one matcher twice as slow
    relative to it fails), the machine ratio is no reason to retry and nothing is called
    contended; on the same model the same re-timing is retried and refused as today."""
    from tfloc.evaluation.contention import Contention
    from tfloc.harness.runner import cpu_model
    from tfloc.harness.timing_pass import ContendedError
    from tfloc.harness.timing_verify import verify_pass
    from tfloc.io.table import write
    from tfloc.io.tables import TIMING

    run_dir = _copy(small_run, tmp_path)
    timing_pass(run_dir, 1, 1, allow_contended=True, draw=write_timing_md, log=lambda s: None)
    doc = _doc(run_dir)
    assert doc["timing"]["sessions"][-1]["cpu"] == cpu_model()  # the pass records the model it ran on
    rows = pd.read_csv(run_dir / "timing.csv")
    ms = {"tf-plus": 2.0, "o3d-icp": 6.0, "stay": 0.5}
    write(run_dir / "timing.csv", TIMING, [TimingRow(r.dataset, str(r.scan_id), r.group, r.matcher, r.position,
                                                  ms[r.matcher], ms[r.matcher]) for r in rows.itertuples()])
    doc["timing"]["sessions"][-1].update(cpu="Fake CPU 9000", contention=Contention(4.0, 4.0, 4.2, 10, 0.0).to_record())
    (run_dir / "run.json").write_text(json.dumps(doc))
    line = (f"timed on Fake CPU 9000, this is {cpu_model()}: absolute CPU times are not comparable; "
            "comparing the matchers' ratios to one another, measured side by side")

    calls: list[int] = []
    _retimed_as(run_dir, monkeypatch, {"tf-plus": 1.8, "o3d-icp": 1.8, "stay": 1.8}, calls)
    assert main(["timing", str(run_dir), "--verify", "--wait", "0"]) == 0 and calls == [1]
    out = capsys.readouterr().out
    assert line in out.splitlines() and "contended" not in out.lower() and "machine now / then" not in out
    assert "committed/tf-plus" in out and "now/tf-plus" in out and "now/committed" in out
    assert out.strip().splitlines()[-1] == (f"{run_dir}: the committed timing pass agrees within ×1.3 for every "
                                            "matcher's ratio to tf-plus (ratios 1.00–1.00)")

    _retimed_as(run_dir, monkeypatch, {"tf-plus": 1.8, "o3d-icp": 3.6, "stay": 1.8}, calls)
    logged: list[str] = []
    assert not verify_pass(run_dir, retries=2, wait_s=0, log=logged.append)
    assert logged[-1] == (f"{run_dir}: the committed timing pass does NOT agree within ×1.3 in the matchers' "
                          "ratios to tf-plus: o3d-icp")

    calls.clear()                             # the same model: the machine ratio refuses it, as before
    _retimed_as(run_dir, monkeypatch, {"tf-plus": 1.8, "o3d-icp": 1.8, "stay": 1.8}, calls)
    with pytest.raises(ContendedError, match=r"contended on each of 3 tries \(the calibration's best round is ×4\.00"):
        verify_pass(run_dir, retries=2, wait_s=0, log=lambda s: None, cpu="Fake CPU 9000")
    assert calls == [1, 1, 1]

    del doc["timing"]["sessions"][-1]["cpu"]  # a record made before the pass named its CPU
    doc["machine"]["cpu"] = "Fake CPU 9000"
    (run_dir / "run.json").write_text(json.dumps(doc))
    logged.clear()
    assert verify_pass(run_dir, retries=0, log=logged.append)
    assert logged[0] == (f"CPU model: committed pass Fake CPU 9000 (the run's machine.cpu: the timing record "
                         f"names none), this machine {cpu_model()}") and logged[1] == line
