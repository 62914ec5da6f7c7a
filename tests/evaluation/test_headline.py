"""The headline: every matcher ranked by its mode's success measure, its interval, error and CPU,
and a paired verdict against the next one down; every report opens with it."""

from __future__ import annotations

import math

import pytest
from _estimates import frame, row, synthetic_run

from tfloc.cli.report import make_report as write_report
from tfloc.core.rows.headline import POOLED
from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.headline import headline
from tfloc.evaluation.metrics import prepare
from tfloc.evaluation.stats import wilson
from tfloc.io.table import read_rows, write
from tfloc.io.tables import HEADLINE

THR = Thresholds()


def _rows(successes: dict[str, int], n: int = 40, dataset: str = "d", cpu: dict | None = None) -> list[dict]:
    """``n`` scans; matcher m succeeds on its first ``successes[m]`` of them (then 0.5 m off)."""
    out = []
    for m, k in successes.items():
        for i in range(n):
            out.append(row(m, 0.01 if i < k else 0.5, 0.5, dataset=dataset, scan_id=f"s{i}",
                           cpu_s=(cpu or {}).get(m, 0.002), runtime_s=0.01))
    return out


def test_matchers_are_ranked_best_first_with_wilson_intervals() -> None:
    p = prepare(frame(_rows({"a": 20, "b": 38, "c": 30})), THR)
    rows = headline(p, {"d": "single"}, THR)
    assert [r.matcher for r in rows] == ["b", "c", "a"] and [r.rank for r in rows] == [1, 2, 3]
    b = rows[0]
    lo, hi = wilson(38, 40)
    assert b.value_pct == pytest.approx(95.0) and b.lo_pct == pytest.approx(100 * lo) and b.hi_pct == pytest.approx(100 * hi)
    assert b.measure == "success" and b.n == 40 and b.scope == "d" and b.error == "median error"
    assert b.cpu_ms == pytest.approx(2.0) and b.error_cm == pytest.approx(1.0)


def test_the_verdict_against_the_next_is_the_paired_test() -> None:
    # b beats c on 8 scans and never loses: ahead; c and a differ by 1 scan: tied
    p = prepare(frame(_rows({"a": 29, "b": 38, "c": 30})), THR)
    b, c, a = headline(p, {"d": "single"}, THR)
    assert b.verdict == "ahead" and b.next_matcher == "c" and b.p_holm < 0.05
    assert c.verdict == "tied" and c.next_matcher == "a" and c.p_holm > 0.05
    assert a.verdict == "" and a.next_matcher == "" and math.isnan(a.p_holm)


def test_ties_are_broken_by_error_then_cpu() -> None:
    p = prepare(frame(_rows({"slow": 30, "fast": 30}, cpu={"slow": 0.01, "fast": 0.001})), THR)
    fast, slow = headline(p, {"d": "single"}, THR)
    assert (fast.matcher, slow.matcher) == ("fast", "slow") and fast.verdict == "tied"


def test_several_datasets_get_a_pooled_table_and_one_each() -> None:
    p = prepare(frame(_rows({"a": 10, "b": 20}, dataset="x") + _rows({"a": 30, "b": 20}, dataset="y")), THR)
    rows = headline(p, {"x": "single", "y": "single"}, THR)
    assert {r.scope for r in rows} == {POOLED, "x", "y"}
    pooled = [r for r in rows if r.scope == POOLED]
    assert [r.matcher for r in pooled] == ["a", "b"] and pooled[0].n == 80
    assert [r.matcher for r in rows if r.scope == "x"] == ["b", "a"]


def test_tracking_pools_over_sequences_with_a_bootstrap_interval() -> None:
    rows = _rows({"t": 35, "u": 10}, dataset="s1") + _rows({"t": 30, "u": 12}, dataset="s2")
    p = prepare(frame(rows), THR)
    out = headline(p, {"s1": "sequence", "s2": "sequence"}, THR)
    pooled = [r for r in out if r.scope == POOLED]
    t = pooled[0]
    assert t.matcher == "t" and t.measure == "tracked" and t.error == "APE RMSE"
    assert t.value_pct == pytest.approx(100 * 65 / 80) and t.lo_pct <= t.value_pct <= t.hi_pct


def test_headline_csv_round_trips(tmp_path) -> None:
    p = prepare(frame(_rows({"a": 20, "b": 38})), THR)
    rows = headline(p, {"d": "single"}, THR)
    write(tmp_path / "h.csv", HEADLINE, rows)
    back = read_rows(tmp_path / "h.csv", HEADLINE)
    assert [r.matcher for r in back] == ["b", "a"] and back[0].verdict == rows[0].verdict
    assert back[1].verdict == "" and math.isnan(back[1].p_holm)


def test_a_report_opens_with_its_headline_table(tmp_path) -> None:
    run = synthetic_run(tmp_path / "run")
    text = write_report(run, with_figures=False).report.read_text()
    first_table = next(i for i, ln in enumerate(text.splitlines()) if ln.startswith("|"))
    before = text.splitlines()[:first_table]
    assert "## Headline" in before and not any(ln.startswith("## ") and ln != "## Headline" for ln in before)
    assert text.splitlines()[first_table].startswith("| # | matcher | success % [95 % CI]")
    assert (run / "headline.csv").is_file()
