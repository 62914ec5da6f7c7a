"""The contention probe's arithmetic and verdict (tfloc.evaluation.contention) from fake readings,
its /proc/stat parsing, and the records of passes made before the probe."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from tfloc.evaluation.contention import (
    MAX_INFLATION,
    MAX_NEIGHBOUR_CORES,
    NOT_MEASURED,
    Contention,
    assess,
    describe,
    mark,
)
from tfloc.evaluation.timing import between_ratios, outside, verify_ratios
from tfloc.harness.contention import parse_proc_stat


def test_inflation_is_the_rounds_median_over_the_minimum_and_neighbours_exclude_this_process():
    c = assess([5.0, 5.2, 5.1], [5.5, 6.0, 7.0, 8.0, 9.0], busy_s=30.0, own_s=20.0, wall_s=20.0,
               steal_s=1.0, loadavg=(1.5, 2.5))
    assert c.calib_quiet_ms == 5.0 and c.calib_min_ms == 5.0 and c.calib_median_ms == 7.0 and c.rounds == 5
    assert c.inflation == pytest.approx(1.4)
    assert c.neighbour_cores == pytest.approx(0.5) and c.steal_cores == pytest.approx(0.05)
    assert c.contended and c.reasons() == ["calibration ×1.40 its minimum", "neighbours used 0.50 core"]
    assert mark(c) == "contended (×1.40 inflated)"
    assert describe(c).startswith("CONTENDED (") and "limits ×1.25 and 0.25 core" in describe(c)
    # a round faster than the reference lowers the minimum; a non-positive reading is ignored
    d = assess([5.0], [4.0, 4.2, 0.0, -1.0], 10.0, 9.9, 10.0)
    assert d.calib_min_ms == 4.0 and d.rounds == 2 and d.neighbour_cores == pytest.approx(0.01)


@pytest.mark.parametrize(("rounds", "busy", "contended"), [
    ([5.0] * 9 + [5.0 * MAX_INFLATION * 0.99], 10.0 + 10 * MAX_NEIGHBOUR_CORES * 0.9, False),
    ([5.0] * 4 + [5.0 * MAX_INFLATION * 1.01] * 5, 10.0, True),          # the calibration slowed
    ([5.0] * 9, 10.0 + 10 * MAX_NEIGHBOUR_CORES * 1.1, True),              # a neighbour, no slow-down
])
def test_a_pass_is_contended_when_either_signal_is_over_its_threshold(rounds, busy, contended):
    c = assess([5.0], rounds, busy_s=busy, own_s=10.0, wall_s=10.0)
    assert c.contended is contended and (mark(c) != "") is contended
    assert describe(c).startswith("CONTENDED" if contended else "quiet")


def test_unreadable_proc_stat_leaves_the_calibration_signal():
    c = assess([5.0], [5.0, 7.0, 7.0], math.nan, 1.0, 2.0)
    assert math.isnan(c.neighbour_cores) and c.contended and "neighbours' CPU not read" in describe(c)
    assert not assess([5.0], [5.0], math.nan, 1.0, 2.0).contended
    empty = assess([], [], 0.0, 0.0, 0.0)
    assert math.isnan(empty.inflation) and not empty.contended


def test_the_record_round_trips_and_older_records_are_not_measured():
    c = assess([5.0], [5.0, 8.0], 12.0, 10.0, 10.0)
    r = c.to_record()
    assert r["contended"] is True and r["inflation"] == pytest.approx(1.3)
    assert Contention.from_record(r) == c and Contention.from_record(r).contended
    assert r["steal_cores"] is None  # NaN is written as null
    for old in (None, "high", [1, 2]):
        assert Contention.from_record(old) is None
    assert describe(None) == NOT_MEASURED and mark(None) == ""
    partial = Contention.from_record({"calib_min_ms": 5.0, "calib_median_ms": 5.1, "rounds": "x"})
    assert partial.rounds == 0 and not partial.contended and math.isnan(partial.neighbour_cores)
    # a pass judged under other thresholds keeps its own
    strict = Contention.from_record({**r, "thresholds": {"inflation": 2.0, "neighbour_cores": 0.1}})
    assert strict.reasons() == ["neighbours used 0.20 core"]


def test_proc_stat_busy_and_steal():
    text = "cpu  100 20 30 1000 40 5 6 7 0 0\ncpu0 50 10 15 500 20 2 3 3 0 0\nintr 1\n"
    assert parse_proc_stat(text, 100) == (pytest.approx(1.61), pytest.approx(0.07))
    assert parse_proc_stat("cpu  1 2 3 4\n", 1) == (6.0, 0.0)  # an old kernel: no irq/steal columns
    with pytest.raises(ValueError):
        parse_proc_stat("intr 1\n", 100)


def test_verify_compares_medians_on_the_scans_both_passes_timed():
    then = pd.DataFrame([{"dataset": "d", "scan_id": f"s{i}", "matcher": m, "cpu_ms": c * (i + 1)}
                         for i in range(5) for m, c in (("a", 2.0), ("b", 10.0))])
    now = then[then["scan_id"] != "s4"].assign(cpu_ms=lambda t: t["cpu_ms"] * t["matcher"].map({"a": 1.0, "b": 2.0}))
    v = verify_ratios(then, now).set_index("matcher")
    assert v.loc["a", "n"] == 4 and v.loc["a", "committed_ms"] == pytest.approx(5.0)
    assert v.loc["a", "ratio"] == pytest.approx(1.0) and v.loc["b", "ratio"] == pytest.approx(2.0)


def test_between_matchers_a_uniform_slowdown_cancels_and_a_relative_one_does_not():
    """On another CPU model the matchers' ratios to the reference are compared: a machine ×1.8
    slower throughout leaves them as they were (the absolute ratios all fail), one matcher twice
    as slow relative to the reference fails alone."""
    then = pd.DataFrame([{"dataset": "d", "scan_id": f"s{i}", "matcher": m, "cpu_ms": c * (i + 1)}
                         for i in range(5) for m, c in (("tf-plus", 2.0), ("b", 10.0), ("c", 1.0))])
    uniform = verify_ratios(then, then.assign(cpu_ms=then["cpu_ms"] * 1.8))
    assert outside(uniform, 1.3) == ["tf-plus", "b", "c"]
    b = between_ratios(uniform, "tf-plus").set_index("matcher")
    assert b.loc["b", "committed_to_ref"] == pytest.approx(5.0) and b.loc["b", "now_to_ref"] == pytest.approx(5.0)
    assert b["ratio"].to_numpy() == pytest.approx([1.0, 1.0, 1.0]) and b.loc["c", "n"] == 5
    assert outside(between_ratios(uniform, "tf-plus"), 1.3) == []
    slow_b = then.assign(cpu_ms=then["cpu_ms"] * 1.8 * then["matcher"].map({"tf-plus": 1.0, "b": 2.0, "c": 1.0}))
    b = between_ratios(verify_ratios(then, slow_b), "tf-plus")
    assert outside(b, 1.3) == ["b"] and b.set_index("matcher").loc["b", "ratio"] == pytest.approx(2.0)
    assert outside(between_ratios(uniform, "c"), 1.3) == []  # any reference: the same cancellation
    apart = then.assign(scan_id=then["scan_id"].where(then["matcher"] != "tf-plus", "other"))
    no_ref = between_ratios(verify_ratios(then, apart), "tf-plus")  # the reference timed on no common scan
    assert no_ref["ratio"].isna().all() and outside(no_ref, 1.3) == ["tf-plus", "b", "c"]
    with pytest.raises(ValueError, match="reference matcher 'x' is not in the re-timing"):
        between_ratios(uniform, "x")
