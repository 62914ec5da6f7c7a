"""A robot owner's recording without truth, end to end: tfloc bench on it judges the trackers
without truth and reports them (the report opens with the truth-free ranking, headline.csv has
truth_free_score, no truth-based figure), tfloc site shows its column; bad input to the verdict
is one line. The recording: the first 300 scans of the bundled real-csail-native-no-truth."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from _paths import ROOT
from test_first_hour import ENV, one_line, tfloc

SOURCE = ROOT / "data" / "scenarios" / "real-csail-native-no-truth"
TRACKERS = "tf-plus-track,csm-corr-track,kiss-icp-track,odometry"


def _slice(out: Path, scans: int = 300) -> Path:
    doc = json.loads((SOURCE / "scenario.json").read_text())
    doc["map"] = str((SOURCE / doc["map"]).resolve())
    doc["name"] = "my-robot"
    out.mkdir(parents=True)
    (out / "scenario.json").write_text(json.dumps(doc))
    with open(SOURCE / "scans.csv") as src, open(out / "scans.csv", "w") as dst:
        for i, line in enumerate(src):
            if i > scans:
                break
            dst.write(line)
    return out


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("owner")
    data = _slice(root / "data" / "my-robot")
    out = root / "results" / "native-no-truth"  # the run the site's tracking page names
    r = tfloc("bench", str(data), "--matchers", TRACKERS, "--out", str(out), "--no-progress")
    assert r.returncode == 0, r.stderr
    assert "tfloc verdict" in r.stderr and "tfloc report" in r.stderr
    return out


def test_headline_ranks_by_the_truth_free_verdict(run: Path) -> None:
    h = pd.read_csv(run / "headline.csv")
    assert set(h["matcher"]) == set(TRACKERS.split(","))
    assert (h["measure"] == "truth-free").all() and h["error_cm"].isna().all()
    assert (h["truth_free_score"] == h["value_pct"]).all()
    assert h.sort_values("rank")["matcher"].iloc[-1] == "odometry"  # dead reckoning drifts off the map


def test_report_opens_with_the_ranking_and_prints_no_truth_figure(run: Path) -> None:
    text = (run / "report.md").read_text()
    head = text.split("## Headline", 1)[1]
    first = head.split("\n\n", 2)[1]
    assert first.startswith("**Tracking without ground truth: the truth-free verdict**")
    assert "believed tracked % [95 % CI]" in head.split("## Tracking", 1)[0]
    assert "APE" not in head.split("## Tracking", 1)[0]
    assert "error over distance" not in text and "tracked % [95 % CI over sequences]" not in text
    assert "## Without ground truth" in text and "Recording checks" in text
    v = pd.read_csv(run / "verdict.csv")
    assert {"score_pct", "fit_pct", "consensus_pct", "odometry_pct", "reconverged_pct"} <= set(v.columns)
    assert not (run / "verdict_agreement.csv").exists()  # nothing to check it against


def test_site_shows_the_truth_free_column(run: Path, tmp_path: Path) -> None:
    site = tmp_path / "site"
    r = tfloc("site", "--results", str(run.parent), "--out", str(site))
    assert r.returncode == 0, r.stderr
    html = (site / "index.html").read_text()
    assert "native-no-truth/sequence/my-robot" in html and "my-robot (no truth)" in html


def test_verdict_bad_input_is_one_line(tmp_path: Path) -> None:
    assert "no estimates.csv" in one_line(tfloc("verdict", str(tmp_path)))
    assert "min_methods must be >= 1" in one_line(tfloc("verdict", str(tmp_path), "--sweep", "min_methods=0"))
    assert "give KEY=V1,V2" in one_line(tfloc("verdict", str(tmp_path), "--sweep", "nope"))
    assert subprocess.run([sys.executable, "-m", "tfloc.cli", "verdict", "--help"], env=ENV,
                          capture_output=True, text=True).returncode == 0
