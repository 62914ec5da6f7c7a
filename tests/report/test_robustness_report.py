"""The robustness section: cells from a prepared run, paired changes, the markdown, the axes."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from tfloc.core.rows.robustness import RobustnessRow
from tfloc.evaluation.robustness import Axis, axes_of, paired_changes
from tfloc.evaluation.robustness import robustness_cells as cell_rows
from tfloc.io.table import frame_of
from tfloc.report.robustness import robustness_figure, robustness_markdown, robustness_table


def robustness_cells(p: pd.DataFrame, axes: dict) -> pd.DataFrame:
    """The cells as ``robustness.csv`` holds them (typed rows as a table)."""
    return frame_of(cell_rows(p, axes), RobustnessRow)


def _prepared() -> pd.DataFrame:
    rows = []
    # matcher a: 9/10 on as-built, 6/10 on hits-only (loses scans 0-2, gains none)
    # matcher b: 5/10 on both, but on different scans (lost 2, gained 2)
    for ds, ok_a, ok_b in (("x-built", range(1, 10), range(0, 5)), ("x-hits", range(3, 9), range(2, 7))):
        for i in range(10):
            for m, ok in (("a", ok_a), ("b", ok_b)):
                rows.append({"dataset": ds, "scan_id": f"s{i}", "matcher": m, "truth": True,
                             "outcome_eval": "success" if i in ok else "local-optimum",
                             "dist_err_cm": 1.0 if i in ok else 50.0, "cpu_ms": 3.0})
    rows.append({"dataset": "other", "scan_id": "s0", "matcher": "a", "truth": True,
                 "outcome_eval": "success", "dist_err_cm": 1.0, "cpu_ms": 3.0})
    return pd.DataFrame(rows)


AXES = {"x-built": Axis("x", "as-built"), "x-hits": Axis("x", "hits-only")}


def test_cells_count_successes_with_wilson_intervals() -> None:
    cells = robustness_cells(_prepared(), AXES).set_index(["matcher", "style"])
    assert cells.loc[("a", "as-built"), "k"] == 9 and cells.loc[("a", "as-built"), "n"] == 10
    assert cells.loc[("a", "hits-only"), "rate"] == pytest.approx(60.0)
    lo, hi = cells.loc[("a", "as-built"), ["lo", "hi"]]
    assert 55 < lo < 90 < hi < 100                     # Wilson 95 % of 9/10: 59.6–98.2
    assert set(cells.reset_index()["log"]) == {"x"}    # the dataset without an axis is left out


def test_paired_changes_against_the_reference_style() -> None:
    ch = paired_changes(_prepared(), AXES).set_index("matcher")
    assert ch.loc["a", "change_pts"] == pytest.approx(-30.0) and ch.loc["a", "lost"] == 3
    assert ch.loc["b", "change_pts"] == pytest.approx(0.0)
    assert (ch.loc["b", "lost"], ch.loc["b", "gained"]) == (2, 2)
    assert (ch["reference"] == "as-built").all() and (ch["n"] == 10).all()


def test_markdown_and_figure(tmp_path: Path) -> None:
    p = _prepared()
    cells, changes = robustness_cells(p, AXES), paired_changes(p, AXES)
    t = robustness_table(cells, "x")
    assert t.splitlines()[0] == "| matcher | as-built (n=10) | hits-only (n=10) |"
    assert "| a | 90.0% [60–98] | 60.0% [31–83] |" in t
    md = robustness_markdown(cells, changes, "figures/robustness.png")
    assert "## Robustness" in md and "−3/+0" in md and "![success by style](figures/robustness.png)" in md
    assert robustness_figure(cells, tmp_path / "f.png").stat().st_size > 1000


def test_axes_come_from_the_scenario_fields() -> None:
    got = axes_of([("d1", {"axis": {"log": "intel", "style": "thick-1"}}), ("d2", {}),
                   ("d3", {"axis": {"log": 3}})])
    assert got == {"d1": Axis("intel", "thick-1")}
