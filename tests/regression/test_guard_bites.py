"""The guard must be able to fail: a deliberately degraded `tf` makes it report regressions."""

from __future__ import annotations

import os

import numpy as np
import pandas as pd
from _paths import ROOT

from tfloc.cli import guard as verb
from tfloc.cli.guard import run_subset
from tfloc.evaluation import guard
from tfloc.harness.config import MatcherSpec, load_config
from tfloc.io.table import read_frame
from tfloc.io.tables import GUARD


def test_degraded_tf_is_caught(tmp_path):
    os.chdir(ROOT)
    # a straw threshold of 0 finds no corner candidates: only the scan's end points remain
    broken = MatcherSpec.make("tf", {"straw_t": 0.0}, label="tf")
    cfg = load_config(ROOT / verb.CONFIG).with_overrides(
        out=tmp_path / "run", matchers=(broken,), limit_per_group=3)
    current = run_subset(cfg, progress=False)
    diff = guard.compare(current, read_frame(ROOT / verb.REFERENCE, GUARD))
    worse = diff[diff.worse]
    assert len(worse), "the guard did not notice a tf that finds no corners"
    assert set(worse.matcher) == {"tf"}
    assert "success_rate_pct" in set(worse.metric)
    table = guard.format_table(diff)
    assert "success_rate_pct" in table and "tf" in table


def test_compare_rules_on_a_hand_made_example():
    ref = pd.DataFrame([{"matcher": "m", "group": "g", "n": 20, "success_rate_pct": 90.0,
                         "dist_mean_cm": 5.0, "dist_median_cm": 1.0, "orient_mean_deg": 0.5,
                         "orient_median_deg": 0.1, "n_local_optimum": 2, "n_ambiguous": 0,
                         "n_no_answer": 0}])
    ok = ref.assign(success_rate_pct=85.0, dist_mean_cm=5.0 * 1.02 + 0.05, n_local_optimum=3)
    assert not guard.compare(ok, ref).worse.any()        # exactly at every tolerance
    bad = ref.assign(success_rate_pct=80.0, dist_median_cm=1.2, n_ambiguous=2)
    worse = guard.compare(bad, ref)
    assert set(worse[worse.worse].metric) == {"success_rate_pct", "dist_median_cm", "n_ambiguous"}
    missing = guard.compare(ref.assign(group="other"), ref)
    assert missing.worse.all()                            # a group that vanished is a regression
    assert np.isclose(guard.RULES[0].allowed(90.0, 20), 85.0)


def test_update_records_the_code_and_configuration_beside_the_reference(tmp_path):
    """``tfloc guard --update`` writes the reference and the run.json of the run that made it."""
    from tfloc.cli import main

    os.chdir(ROOT)
    cfg = tmp_path / "tiny.toml"
    cfg.write_text('name = "tiny"\nout = "' + str(tmp_path / "run") + '"\n'
                   'datasets = ["data/scenarios/office-pool"]\nmatchers = ["odometry"]\nlimit_per_group = 1\n')
    ref = tmp_path / "ref" / "summary.csv"
    ref.parent.mkdir()
    assert main(["guard", "--config", str(cfg), "--reference", str(ref), "--no-tracking", "--update",
                 "--jobs", "1"]) in (0, None)
    record = ref.with_suffix(".run.json")
    assert ref.exists() and record.exists()
    import json

    doc = json.loads(record.read_text())
    assert doc["config"]["name"] == "tiny" and "commit" in doc["git"] and doc["versions"]["numpy"]
