"""Report generation on synthetic runs: tables, summary.csv, figures; missing truth; the CLI."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from tests._estimates import frame, row, synthetic_run
from tfloc.cli import main
from tfloc.cli.report import make_report as write_report
from tfloc.errors import ResultsError
from tfloc.evaluation.metrics import METRIC_COLUMNS
from tfloc.evaluation.summary import SUMMARY_KEYS

FIGURES = {"scenario_errors.png", "basin.png", "error_cdf.png", "runtime.png", "outcomes.png"}


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    run = synthetic_run(tmp_path_factory.mktemp("run") / "synthetic")
    files = write_report(run)
    return run, files, files.report.read_text()


def test_report_has_the_papers_tables_with_published_and_measured_rows(report):
    _, _, md = report
    for title in ("### Table 2 — Scenario I", "### Table 3 — Scenario II", "### Table 4 — Scenario III"):
        assert title in md
    assert "| Scenario | Sample | Source | Mean Distance Error (cm) | Mean Orientation Error (°) | " \
           "Distance Improvement (%) | Orientation Improvement (%) |" in md
    for published in ("7.7878", "64.3136", "0.4368", "10.4595", "85.5073"):
        assert published in md
    assert md.count("tfloc `tf` (measured)") == 9      # 3 detail levels + 3 angle + 3 distance bins
    assert "### Scenario II (Table 3 layout): all matchers" in md
    assert "| 2 (5–10°) |" in md and "| 3 (200–300 cm) |" in md


def test_report_states_definitions_thresholds_and_exclusions(report):
    _, _, md = report
    assert "mean of the per-scan values" in md
    assert "distance error ≤ 10 cm and orientation error ≤ 2°" in md
    assert "excl.)" in md                                   # tf has a timeout and an error per dataset
    assert "Commit: `abc123`" in md
    assert "5 × `error:ValueError: synthetic`" in md   # one per dataset


def test_report_has_per_dataset_and_scan_to_scan_tables(report):
    _, _, md = report
    assert "### office-pool" in md and "Success rate (%) [95 % CI] by initial distance offset" in md
    assert "### real-x-relations" in md and "Trans. error (m) mean ± std" in md
    section = md.split("### real-x-relations")[1]
    assert "| `tf` | loop |" in section and "| `tf` | all |" in section
    pooled = md.split("## Scan-to-map datasets pooled (detail-1, detail-2, detail-3, office-pool)")[1]
    assert "Scan-to-scan datasets are left out" in pooled


def test_summary_csv_has_every_grouping(report):
    run, files, _ = report
    t = pd.read_csv(run / "summary.csv")
    assert list(t.columns) == SUMMARY_KEYS + list(METRIC_COLUMNS)
    assert {"scenario-I", "scenario-II", "scenario-III", "dataset", "dataset-dist_bin",
            "dataset-angle_bin", "dataset-group", "overall", "overall-scan-to-map"} <= set(t["grouping"])
    # the relations dataset is scan-to-scan (by its name here): grouped by its groups, not binned
    assert not ((t["grouping"] == "dataset-dist_bin") & (t["dataset"] == "real-x-relations")).any()
    assert set(t.loc[t["grouping"] == "overall", "matcher"]) == {"tf", "csm-corr"}


def test_all_figures_are_written_as_png(report):
    run, files, md = report
    assert {f.name for f in files.figures} == FIGURES
    for f in files.figures:
        assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and f.stat().st_size > 10_000
        assert f"(figures/{f.name})" in md


def test_report_without_truth_does_not_crash(tmp_path):
    run = synthetic_run(tmp_path / "blind", truth=False)
    files = write_report(run)
    md = files.report.read_text()
    assert "No scan in this run has ground truth" in md
    assert "Table 2" not in md
    assert {f.name for f in files.figures} == {"runtime.png"}


def test_thresholds_override_rescoring(tmp_path):
    run = tmp_path / "r"
    run.mkdir()
    frame([row("A", 0.05, 0.5, scan_id="a"), row("A", 0.01, 0.5, scan_id="b")]).to_csv(
        run / "estimates.csv", index=False)
    assert main(["report", str(run), "--no-figures"]) == 0
    assert "run.json is missing" in (run / "report.md").read_text()
    s = pd.read_csv(run / "summary.csv")
    assert s.loc[s["grouping"] == "overall", "success_rate_pct"].iloc[0] == 100.0
    assert main(["report", str(run), "--no-figures", "--success-cm", "2"]) == 0
    s = pd.read_csv(run / "summary.csv")
    assert s.loc[s["grouping"] == "overall", "success_rate_pct"].iloc[0] == 50.0
    assert "distance error ≤ 2 cm" in (run / "report.md").read_text()


def test_not_a_run_directory(tmp_path, capsys):
    with pytest.raises(ResultsError, match="no estimates.csv"):
        write_report(tmp_path)
    assert main(["report", str(tmp_path)]) == 2
    assert "no estimates.csv" in capsys.readouterr().err


def test_missing_column_is_named(tmp_path):
    frame([row()]).drop(columns=["dist_err_m"]).to_csv(tmp_path / "estimates.csv", index=False)
    (tmp_path / "run.json").write_text(json.dumps({}))
    with pytest.raises(ResultsError, match="dist_err_m"):
        write_report(tmp_path)


def test_empty_run_is_a_one_line_error(tmp_path):
    frame([]).to_csv(tmp_path / "estimates.csv", index=False)
    with pytest.raises(ResultsError, match="no results yet"):
        write_report(tmp_path)


def test_a_sweeps_line_figures_show_the_first_label_and_the_most_successful_others():
    from tfloc.core.thresholds import Thresholds
    from tfloc.evaluation.metrics import prepare
    from tfloc.report.report import line_figure_matchers

    order = [f"m{i:02d}" for i in range(20)]          # m00 first; m19 succeeds most often
    rows = [row(m, dist_m=0.01 if k < i else 1.0, scan_id=f"s{k}")
            for i, m in enumerate(order) for k in range(20)]
    p = prepare(frame(rows), Thresholds())
    shown = line_figure_matchers(p, order, most=8)
    assert shown == ["m00", "m19", "m18", "m17", "m16", "m15", "m14", "m13"]


def test_a_sweeps_bar_figures_turn_horizontal(tmp_path):
    from matplotlib.image import imread

    from tfloc.core.thresholds import Thresholds
    from tfloc.evaluation.metrics import prepare
    from tfloc.report.figures import MANY_MATCHERS, fig_outcomes

    many_n = MANY_MATCHERS + 30
    for n, name in ((3, "few"), (many_n, "many")):
        rows = [row(f"m{i:02d}", scan_id=f"s{k}") for i in range(n) for k in range(3)]
        fig_outcomes(prepare(frame(rows), Thresholds()), tmp_path / f"{name}.png")
    few, many = imread(tmp_path / "few.png"), imread(tmp_path / "many.png")
    assert few.shape[1] > few.shape[0]                   # wide: matchers along x
    assert many.shape[0] > many.shape[1]                 # tall: one row per label,
    assert many.shape[0] / many_n > 20                   # each over 20 pixels high
