"""Global-localization metrics on hand-made rows: top-1, top-5, ambiguous, cost against area."""

from __future__ import annotations

import json
import math

import pytest

from tfloc.core.pose import Pose
from tfloc.core.thresholds import Thresholds
from tfloc.errors import ResultsError
from tfloc.evaluation.relocalization import (
    free_area_m2,
    hypotheses_from_info,
    hypotheses_info,
    result_from_row,
    scan_result,
    summarize,
)
from tfloc.evaluation.stats import wilson

T = Thresholds()
TRUTH = Pose(2.0, 3.0, 0.5)
NEAR = Pose(2.05, 3.0, 0.5 + math.radians(1.0))
FAR = Pose(7.0, 1.0, -2.0)


def _row(est: Pose | None, hyps: list[Pose] | None = None, status: str = "ok", score_est: float = 0.2,
         score_true: float = 0.3, cpu_s: float = 0.05, dataset: str = "d", matcher: str = "m") -> dict:
    info = {} if hyps is None else {"hypotheses": hypotheses_info(hyps)}
    e = est or Pose(math.nan, math.nan, math.nan)
    return {"dataset": dataset, "matcher": matcher, "scan_id": "s", "status": status,
            "true_x": str(TRUTH.x), "true_y": str(TRUTH.y), "true_theta": str(TRUTH.theta),
            "est_x": "" if est is None else str(e.x), "est_y": "" if est is None else str(e.y),
            "est_theta": "" if est is None else str(e.theta), "score_est": str(score_est),
            "score_true": str(score_true), "cpu_s": str(cpu_s), "info": json.dumps(info)}


def test_top1_success_is_top5_success() -> None:
    r = result_from_row(_row(NEAR, [NEAR, FAR]), T)
    assert r.top1 and r.top5 and r.ambiguous is False and r.answered


def test_a_right_second_hypothesis_is_top5_not_top1() -> None:
    r = result_from_row(_row(FAR, [FAR, Pose(9, 9, 0), NEAR]), T)
    assert not r.top1 and r.top5


def test_a_right_sixth_hypothesis_does_not_count() -> None:
    hyps = [FAR] + [Pose(9.0 + k, 9.0, 0.0) for k in range(4)] + [NEAR]
    assert len(hypotheses_info(hyps)) == 5  # what the harness stores
    r = scan_result("d", "m", TRUTH, FAR, hyps, T)
    assert not r.top1 and not r.top5


def test_ambiguous_when_the_own_score_prefers_the_wrong_answer() -> None:
    assert result_from_row(_row(FAR, [FAR], score_est=0.2, score_true=0.3), T).ambiguous is True
    assert result_from_row(_row(FAR, [FAR], score_est=0.4, score_true=0.3), T).ambiguous is False
    assert result_from_row(_row(FAR, [FAR], score_est=math.nan), T).ambiguous is None
    # a success is never ambiguous, whatever the scores say
    assert result_from_row(_row(NEAR, [NEAR], score_est=0.9, score_true=0.1), T).ambiguous is False


def test_no_answer_and_invalid_rows() -> None:
    r = result_from_row(_row(None, status="failed"), T)
    assert not r.answered and not r.top1 and not r.top5
    assert result_from_row(_row(None, status="invalid:a global problem"), T) is None
    no_truth = _row(NEAR)
    no_truth["true_x"] = ""
    assert result_from_row(no_truth, T) is None


def test_a_matcher_without_hypotheses_is_scored_on_its_answer() -> None:
    assert result_from_row(_row(NEAR), T).top5
    assert not result_from_row(_row(FAR), T).top5


def test_thresholds_apply_to_every_hypothesis() -> None:
    off = Pose(2.0, 3.0, 0.5 + math.radians(2.5))  # 2.5° off: outside 2°, inside 3°
    assert not scan_result("d", "m", TRUTH, FAR, [FAR, off], T).top5
    assert scan_result("d", "m", TRUTH, FAR, [FAR, off], Thresholds(0.1, 3.0)).top5


def test_bad_hypotheses_are_one_line_errors() -> None:
    assert hypotheses_from_info("") == [] and hypotheses_from_info("{}") == []
    assert hypotheses_from_info({"hypotheses": [[1, 2, 0.5]]}) == [Pose(1.0, 2.0, 0.5)]
    for bad in ("{", "[1]", '{"hypotheses": 3}', '{"hypotheses": [[1, 2]]}',
                '{"hypotheses": [[1, "a", 2]]}', '{"hypotheses": [[1, 2, NaN]]}'):
        with pytest.raises(ResultsError, match="estimates.csv:7"):
            hypotheses_from_info(bad, "estimates.csv:7")


def test_summary_rates_intervals_shares_and_cost() -> None:
    rows = ([_row(NEAR, [NEAR], cpu_s=0.010)] * 6 + [_row(FAR, [FAR, NEAR], cpu_s=0.020)] * 2
            + [_row(FAR, [FAR], score_est=0.1, cpu_s=0.030)] + [_row(None, status="failed", cpu_s=0.040)])
    rows += [_row(NEAR, [NEAR], matcher="other", cpu_s=1.0)]
    (s, o) = summarize([result_from_row(r, T) for r in rows], {"d": 50.0})
    assert (s.dataset, s.matcher, s.n) == ("d", "m", 10)
    assert s.top1 == pytest.approx(0.6) and (s.top1_lo, s.top1_hi) == pytest.approx(wilson(6, 10))
    assert s.top5 == pytest.approx(0.8) and (s.top5_lo, s.top5_hi) == pytest.approx(wilson(8, 10))
    assert s.ambiguous == pytest.approx(0.3) and s.no_answer == pytest.approx(0.1)
    assert s.cpu_ms_median == pytest.approx(10.0)  # median of 6×10, 2×20, 30, 40 ms
    assert s.free_area_m2 == 50.0 and s.ms_per_100m2 == pytest.approx(20.0)
    assert (o.matcher, o.n, o.top1, o.cpu_ms_median) == ("other", 1, 1.0, pytest.approx(1000.0))
    assert math.isnan(summarize([result_from_row(rows[0], T)])[0].free_area_m2)


def test_free_area_of_the_test_room(test_room) -> None:
    # an L-shaped room of 10 × 5 + 8 × 3 = 74 m² minus three small obstacles
    a = free_area_m2(test_room)
    assert 70.0 < a < 74.0
    assert free_area_m2(test_room, clearance=0.3) < a


def test_summarize_rows_names_the_line_of_a_bad_row() -> None:
    from tfloc.evaluation.relocalization import summarize_rows

    good = [(2, _row(NEAR, [NEAR])), (3, _row(None, status="invalid:no guess"))]
    (s,) = summarize_rows(good, T)
    assert s.n == 1 and s.top1 == 1.0
    bad = _row(NEAR)
    bad["info"] = '{"hypotheses": [[1, 2]]}'
    with pytest.raises(ResultsError, match=r"run/estimates.csv:9: info 'hypotheses'\[0\]"):
        summarize_rows([*good, (9, bad)], T, path="run/estimates.csv")


def test_place_rank_and_recall_from_the_proposed_places():
    from tfloc.evaluation.relocalization import place_rank

    truth = Pose(1.0, 2.0, 0.3)
    places = [[5.0, 5.0, 0.3], [1.3, 2.2, 0.5], [1.0, 2.0, 0.3]]   # the second is within 0.5 m, 25°
    assert place_rank(places, truth) == 2
    assert place_rank([[1.0, 2.0, 0.3 + math.radians(30)]], truth) == 0   # too far turned
    assert place_rank([], truth) is None
    row = {"dataset": "d", "matcher": "m", "status": "ok", "true_x": 1.0, "true_y": 2.0, "true_theta": 0.3,
           "est_x": 1.0, "est_y": 2.0, "est_theta": 0.3, "cpu_s": 0.01, "score_est": "", "score_true": "",
           "info": json.dumps({"proposed": places})}
    far = dict(row, info=json.dumps({"proposed": places[:1]}))
    (s,) = summarize([result_from_row(row, Thresholds()), result_from_row(far, Thresholds())])
    assert (s.place_recall1, s.place_recall5, s.place_recall_all) == (0.0, 0.5, 0.5)
    (plain,) = summarize([result_from_row(dict(row, info="{}"), Thresholds())])
    assert math.isnan(plain.place_recall_all)
