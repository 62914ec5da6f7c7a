"""RunDir: a study's run.json checked like a run's and read as one typed record, the timing
pass's record kept across sessions, the verdict's and the derived tables' records, and discard
removing the timing pass with the run."""

from __future__ import annotations

import json

import pytest

from tfloc.errors import ResultsError
from tfloc.io.rundir import RunDir, check_run_doc

BENCH = {"config": {"name": "r", "matchers": [{"label": "tf-plus", "name": "tf-plus", "params": {}}],
                    "success": {"dist_m": 0.1, "orient_deg": 2.0}},
         "datasets": {"d": "data/d"}, "fingerprint": {"tfloc": {"version": "0", "source": "x"}}}
SCALING = {**BENCH, "config": {**BENCH["config"], "kind": "scaling", "scaling": {"scans_per_level": 2}},
           "datasets": {"office-1": "data/maps/office-1.geojson"}, "levels": ["area/vector/1x1"], "done": [],
           "command": "tfloc scaling", "sessions": [{"started": "t", "loadavg_start": [0.5, 0.5, 0.5], "cores": [1]}]}


def test_a_scaling_studys_run_json_is_a_run_json(tmp_path):
    rd = RunDir(tmp_path)
    rd.write_doc(SCALING)
    info = rd.info(required=True)
    assert info.kind == "scaling" and info.done == () and list(info.paths) == ["office-1"] and info.config is None
    assert info.study == {"scans_per_level": 2} and info.command == "tfloc scaling" and info.exists
    assert info.sessions[0].cores == (1,) and info.sessions[0].loadavg_start == (0.5, 0.5, 0.5)
    assert RunDir(tmp_path / "none").info().kind == "bench"
    for bad in ({**SCALING, "done": "all"}, {**SCALING, "levels": [1]}, {**SCALING, "timing": []},
                {**SCALING, "timing": {"sessions": [{"loadavg_start": "high"}]}},
                {**SCALING, "config": {**SCALING["config"], "kind": 3}}):
        with pytest.raises(ResultsError, match="run.json"):
            check_run_doc(bad, tmp_path / "run.json")


def test_the_timing_record_survives_a_new_session_and_goes_with_discard(tmp_path):
    rd = RunDir(tmp_path)
    rd.start_session(BENCH, 4, 0, [1.0, 1.0, 1.0])
    rd.close_session([1.0, 1.0, 1.0])
    fp = {"run": BENCH["fingerprint"], "per_stratum": 4}
    rd.start_timing(fp, [0.1, 0.1, 0.1], fresh=True)
    assert rd.info().timing.complete is False
    rd.close_timing([0.2, 0.2, 0.2], cores=[1])
    record = rd.info().timing
    assert record.complete and record.fingerprint == fp and record.last_session.cores == (1,)
    rd.start_session(BENCH, 4, 4, None)          # tfloc bench again on the complete run
    info = rd.info()
    assert info.timing == record and len(info.sessions) == 2
    rd.start_timing(fp, None, fresh=False)       # the same pass again: its sessions go on
    assert len(rd.info().timing.sessions) == 2
    rd.start_timing({**fp, "per_stratum": 1}, None, fresh=True)   # another pass starts over
    assert len(rd.info().timing.sessions) == 1
    for f in ("estimates.csv", "timing.csv", "timing.md", "scaling.csv"):
        (tmp_path / f).write_text("x\n")
    rd.discard(also=("scaling.csv",))
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    assert rd.info().timing is None


def test_levels_record_progress_in_the_last_session(tmp_path):
    rd = RunDir(tmp_path)
    rd.start_session(SCALING, 10, 0, None, cores=[1])
    rd.record_levels(["area/vector/1x1"], cpu_s=1.5)
    doc = json.loads(rd.run_json.read_text())
    assert doc["done"] == ["area/vector/1x1"] and doc["sessions"][-1]["cpu_s"] == 1.5
    assert doc["sessions"][-1]["cores"] == [1] and len(doc["sessions"]) == 1  # the previous run.json's, none


def test_the_verdict_and_the_derived_tables_record_what_they_were_made_from(tmp_path):
    from tfloc.core.run import DerivedRecord, VerdictRecord

    rd = RunDir(tmp_path)
    rd.start_session(BENCH, 4, 0, None)
    rd.record_verdict(VerdictRecord({"fit_tol_m": 0.05}, True, "abc", "code1"))
    rd.record_derived("tables", DerivedRecord("code2", "abc", None))
    rd.record_derived("report", DerivedRecord("code3", "abc"))
    info = rd.info()
    assert info.verdict == VerdictRecord({"fit_tol_m": 0.05}, True, "abc", "code1")
    assert info.derived == {"tables": DerivedRecord("code2", "abc", None), "report": DerivedRecord("code3", "abc")}
    assert rd.rows_sha256() is None
    (tmp_path / "estimates.csv").write_text("x\n")
    assert len(rd.rows_sha256()) == 64
