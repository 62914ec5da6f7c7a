"""The `tf` matcher end to end on the bundled test room, and its robustness to degenerate input."""

import math

import numpy as np
import pytest
from _tf_cases import TRUE, corridor_problem, few_returns_problem, noisy_scan

import tfloc
from tfloc import Pose, Problem
from tfloc.paper.matcher import TfConfig, TurningFunctionMatcher
from tfloc.paper.shape import scan_corners


def test_tf_improves_a_0p3m_5deg_offset(test_room, lms200):
    ranges = noisy_scan(test_room, lms200, TRUE)
    errs = []
    for k in range(4):  # four directions, alternating heading sign
        a = k * math.pi / 2 + 0.3
        init = Pose(TRUE.x + 0.3 * math.cos(a), TRUE.y + 0.3 * math.sin(a),
                    TRUE.theta + math.radians(5) * (-1) ** k)
        est = tfloc.localize(test_room, lms200, ranges, init, matcher="tf")
        d, th = est.pose.distance_to(TRUE), abs(tfloc.angdiff(est.pose.theta, TRUE.theta))
        assert d < 0.3 and th < math.radians(5), f"direction {k}: not closer than the initial guess"
        errs.append((d, th))
    d, th = np.median(np.array(errs), axis=0)
    assert d < 0.10 and th < math.radians(1.0)          # measured: 4 cm, 0.2°


def test_score_prefers_the_truth(test_room, lms200):
    ranges = noisy_scan(test_room, lms200, TRUE)
    m = TurningFunctionMatcher()
    p = Problem(test_room, lms200, ranges, TRUE)
    assert m.score(p, TRUE) < m.score(p, Pose(TRUE.x + 0.5, TRUE.y, TRUE.theta))


def test_candidate_inside_a_wall_costs_the_penalty(test_room, lms200):
    m = TurningFunctionMatcher()
    p = Problem(test_room, lms200, noisy_scan(test_room, lms200, TRUE), TRUE)
    assert m.score(p, Pose(2.0, 1.4, 0.0)) == TfConfig().penalty     # inside the table


def test_scan_with_too_few_corners_is_a_no_answer_not_a_crash(lms200):
    # a scan with only 2 returns: its polygon (origin + 2 corners) is degenerate at most a triangle;
    # a single return gives < 3 edges
    est = TurningFunctionMatcher().localize(few_returns_problem(lms200, 1))
    assert not est.converged and est.info["status"] == "no-answer"
    assert est.pose == Pose(1, 1, 0)


def test_search_survives_a_map_with_no_features(lms200):
    # a long corridor seen end-on: few corners, many invalid candidates near the walls
    est = TurningFunctionMatcher(max_outer=2).localize(corridor_problem(lms200))
    assert est.pose.is_finite()


def test_config_overrides_and_unknown_parameter():
    assert TurningFunctionMatcher(spacing=0.5).config.spacing == 0.5
    with pytest.raises(tfloc.MatcherError):
        tfloc.get_matcher("tf", no_such_parameter=1)


def test_scan_corners_in_sensor_frame(test_room, lms200):
    c = scan_corners(test_room.raycast(TRUE, lms200), lms200)
    assert c.ndim == 2 and c.shape[1] == 2 and len(c) >= 3
    assert np.hypot(*c.T).max() <= lms200.max_range
