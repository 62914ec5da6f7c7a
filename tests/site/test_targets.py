"""The tracking targets are computed from the rows: the paired verdicts read down the ranks, each
native target met or missed by its own figure, the simulated sequences counted."""

from __future__ import annotations

import math

import pandas as pd

from tfloc.evaluation.headline import HeadlineRow
from tfloc.site.targets import native_checks, simulated_line, standing, targets_markdown


def _rows(scope: str, ranked: list[tuple[str, float, str]]) -> list[HeadlineRow]:
    """Headline rows of one table: (matcher, share %, verdict against the next), best first."""
    return [HeadlineRow("sequence", scope, i + 1, m, "tracked", v, v - 1, v + 1, 100, 3.0, "APE RMSE", 1.0, verdict,
                        ranked[i + 1][0] if i + 1 < len(ranked) else "", math.nan)
            for i, (m, v, verdict) in enumerate(ranked)]


def test_standing_reads_the_paired_verdicts_down_the_ranks():
    assert standing(_rows("a", [("tf-plus-track", 99, "ahead"), ("x", 90, "")])).verdict == "first"
    tied = standing(_rows("a", [("x", 99, "tied"), ("tf-plus-track", 98, "ahead"), ("y", 80, "")]))
    assert (tied.verdict, tied.rank) == ("tied", 2)
    behind = standing(_rows("a", [("x", 99, "ahead"), ("y", 98, "tied"), ("tf-plus-track", 97.5, "")]))
    assert behind.verdict == "behind" and behind.above == ("x",)
    assert standing(_rows("a", [("x", 99, "")])) is None


def _tracking(ds: str, **mine) -> pd.DataFrame:
    base = {"dataset": ds, "tracked": 0.99, "ape_rmse_m": 0.03, "jumps": 0, "max_jump_m": 0.4, "cpu_ms_median": 0.25}
    return pd.DataFrame([{**base, "matcher": "tf-plus-track", **mine},
                         {**base, "matcher": "csm-corr-track", "tracked": 0.97, "cpu_ms_median": 2.0},
                         {**base, "matcher": "odometry", "tracked": 0.1, "cpu_ms_median": 0.001}])


def test_each_native_target_is_met_or_missed_by_its_own_figure():
    rows = _rows("log", [("tf-plus-track", 99, "ahead"), ("csm-corr-track", 97, "")])
    (ok,) = native_checks(rows, _tracking("log"))
    assert ok.missed == () and ok.cheapest == "tf-plus-track"  # odometry is never the answer
    (slow,) = native_checks(rows, _tracking("log", cpu_ms_median=3.0, ape_rmse_m=0.05, jumps=2, max_jump_m=1.6))
    assert slow.missed == ("APE", "jumps", "CPU", "cheapest") and slow.cheapest == "csm-corr-track"
    behind = _rows("log", [("csm-corr-track", 99.5, "ahead"), ("tf-plus-track", 99, "")])
    assert native_checks(behind, _tracking("log"))[0].missed == ("rank",)


def test_the_block_names_its_runs_and_counts_the_simulated_sequences():
    rows = _rows("log", [("tf-plus-track", 99, "ahead"), ("csm-corr-track", 97, "")])
    sim = _rows("seq-a", [("tf-plus-track", 100, "tied"), ("x", 100, "")]) + \
        _rows("seq-b", [("x", 100, "ahead"), ("tf-plus-track", 90, "")]) + _rows("real-c", [("x", 1, "")])
    kinds = {"seq-a": "simulated", "seq-b": "simulated", "real-c": "real"}
    text = targets_markdown(("native", rows, _tracking("log")), ("sequences", sim, kinds))
    assert "`results/native/`" in text and "| log | 99.0 % (first, ahead)" in text and "| met |" in text
    assert "on 1 of 2 sequences; behind on seq-b (`x`); **missed** there." in text
    assert "not yet" in simulated_line([], "sequences", {}) and "not yet" in targets_markdown(None, None)


def test_the_simulated_sequences_are_those_their_scenario_calls_simulated():
    """The kind decides, not the name: a simulated dataset named real-… counts, a real one named seq-… does not."""
    sim = _rows("real-x", [("tf-plus-track", 100, "ahead"), ("x", 90, "")]) + \
        _rows("seq-b", [("x", 100, "ahead"), ("tf-plus-track", 90, "")])
    line = simulated_line(sim, "sequences", {"real-x": "simulated", "seq-b": "real"})
    assert "on 1 of 1 sequences; **met**." in line
    assert "not yet" in simulated_line(sim, "sequences", {})  # kinds unknown: no sequence counted
