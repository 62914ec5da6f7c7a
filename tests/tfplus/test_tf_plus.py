"""The `tf-plus` matcher: accuracy near and far, its objective, degenerate input, configuration."""

import math

import numpy as np
import pytest
from _tf_cases import TRUE, corridor_problem, few_returns_problem, noisy_scan
from _tfplus_oracles import rotation_candidates
from shapely.geometry import box

import tfloc
from tfloc import Pose, Problem, VectorMap
from tfloc.maps.fields import distance_field
from tfloc.paper.shape import ShapeConfig, scan_turning_function
from tfloc.tfplus.matcher import TfPlusConfig, TurningFunctionPlusMatcher
from tfloc.tfplus.refine import RefineConfig, refine


def errors(est, true):
    return est.pose.distance_to(true), abs(tfloc.angdiff(est.pose.theta, true.theta))


def test_recovers_a_0p3m_5deg_offset(test_room, lms200):
    ranges = noisy_scan(test_room, lms200, TRUE)
    for k in range(4):  # four directions, alternating heading sign
        a = k * math.pi / 2 + 0.3
        init = Pose(TRUE.x + 0.3 * math.cos(a), TRUE.y + 0.3 * math.sin(a),
                    TRUE.theta + math.radians(5) * (-1) ** k)
        est = tfloc.localize(test_room, lms200, ranges, init, matcher="tf-plus")
        d, th = errors(est, TRUE)
        assert d < 0.02 and th < math.radians(0.5), f"direction {k}: {d:.3f} m, {math.degrees(th):.2f}°"
        assert est.converged and est.info["status"] == "ok"


def test_recovers_a_2p5m_12deg_offset(test_room, lms200):
    # the robot west of the room's middle, the table and the free-standing wall in view; the
    # guess is 2.5 m north of it, rotated by 12°: one place and heading explain the scan
    true = Pose(2.5, 3.5, 0.3)
    init = Pose(true.x, true.y + 2.5, true.theta - math.radians(12))
    assert test_room.is_free(np.array([init.xy]), 0.2)[0]
    est = tfloc.localize(test_room, lms200, noisy_scan(test_room, lms200, true, seed=3), init,
                         matcher="tf-plus")
    d, th = errors(est, true)
    assert d < 0.02 and th < math.radians(0.5), f"{d:.3f} m, {math.degrees(th):.2f}°"


def test_score_prefers_the_truth(test_room, lms200):
    m = TurningFunctionPlusMatcher()
    p = Problem(test_room, lms200, noisy_scan(test_room, lms200, TRUE), TRUE)
    near = m.score(p, TRUE)
    assert near < m.score(p, Pose(TRUE.x + 0.5, TRUE.y, TRUE.theta))
    assert near < m.score(p, Pose(TRUE.x, TRUE.y, TRUE.theta + math.radians(5)))
    assert near < 0.02                                   # σ = 1 cm noise


@pytest.mark.parametrize("returns", [1, 2])
def test_scan_with_one_or_two_returns_is_a_no_answer(lms200, returns):
    est = TurningFunctionPlusMatcher().localize(few_returns_problem(lms200, returns))
    assert not est.converged and est.info["status"] == "no-answer"
    assert est.pose == Pose(1, 1, 0)


def test_survives_a_corridor_seen_end_on(lms200):
    est = TurningFunctionPlusMatcher().localize(corridor_problem(lms200))
    assert est.pose.is_finite()
    assert abs(est.pose.y - 0.5) < 0.05 and abs(tfloc.angdiff(est.pose.theta, 0.0)) < math.radians(1)


def test_config_overrides_and_bad_parameters():
    m = TurningFunctionPlusMatcher(grid_step=0.1, tf_seed=False)
    assert m.config.grid_step == 0.1 and not m.config.tf_seed
    assert TurningFunctionPlusMatcher(TfPlusConfig(candidates=2)).config.candidates == 2
    assert tfloc.get_matcher("tf-plus").name == "tf-plus"
    with pytest.raises(tfloc.MatcherError):
        tfloc.get_matcher("tf-plus", no_such_parameter=1)
    with pytest.raises(tfloc.errors.ParameterError, match="select"):
        TurningFunctionPlusMatcher(select="nearest")
    with pytest.raises(tfloc.errors.ParameterError, match="tf-plus.*select"):
        tfloc.get_matcher("tf-plus", select="nearest")
    with pytest.raises(tfloc.errors.ParameterError):
        TurningFunctionPlusMatcher(refine_to="scan")


def test_ablation_switches_run(test_room, lms200):
    ranges = noisy_scan(test_room, lms200, TRUE)
    init = Pose(TRUE.x + 0.2, TRUE.y - 0.1, TRUE.theta + 0.05)
    for kw in ({"tf_seed": False}, {"heading_sweep": False}, {"grid": False}, {"select": "tf"},
               {"tie_tolerance": 0.0}, {"beam_check": False}, {"refine_to": "virtual"},
               {"select": "virtual"}, {"coarse_bound": False}, {"coarse_points": 0},
               {"refinement": RefineConfig(faces=False)}):
        est = TurningFunctionPlusMatcher(**kw).localize(Problem(test_room, lms200, ranges, init))
        assert est.pose.distance_to(TRUE) < 0.02, kw
    # without refinement the answer is a grid pose (0.2 m lattice): near, not exact
    est = TurningFunctionPlusMatcher(refine=False).localize(Problem(test_room, lms200, ranges, init))
    assert 0.0 < est.pose.distance_to(TRUE) < 0.5


def test_edge_histogram_recovers_a_pure_rotation(test_room, lms200):
    cfg = ShapeConfig(spacing=0.05)
    real = scan_turning_function(test_room.raycast(TRUE, lms200), lms200, cfg)
    off = Pose(TRUE.x, TRUE.y, TRUE.theta + math.radians(8))
    virtual = scan_turning_function(test_room.raycast(off, lms200), lms200, cfg)
    rots = rotation_candidates(real, virtual, math.radians(20), count=3)
    assert np.min(np.abs(np.degrees(rots) - 8.0)) < 1.0     # real = virtual rotated by +8°


def test_refine_converges_from_10cm_3deg(test_room, lms200):
    pts = lms200.to_points(noisy_scan(test_room, lms200, TRUE))
    start = np.array([[TRUE.x + 0.1, TRUE.y - 0.05, TRUE.theta + math.radians(3)]])
    out = refine(test_room, lms200, pts, start)[0]
    assert math.hypot(out[0] - TRUE.x, out[1] - TRUE.y) < 0.01
    assert abs(tfloc.angdiff(out[2], TRUE.theta)) < math.radians(0.2)


def test_distance_field_is_zero_on_walls_and_truncated_far(test_room):
    f = distance_field(test_room, 0.05, 0.3)
    pts, _ = test_room.sample_points(0.5)
    assert np.all(f(pts) <= 0.05)
    assert np.all(f(np.array([[-50.0, -50.0], [5.0, 100.0]])) == pytest.approx(0.3))


def test_see_through_beams_cost_in_the_score(lms200):
    # a room whose far wall the real scan misses entirely: with the beam check those beams count
    room = VectorMap(outline=box(0, 0, 4, 3))
    pose = Pose(1.0, 1.5, 0.0)
    ranges = room.raycast(pose, lms200)
    ranges[60:120] = np.inf                                   # the beams towards x = 4
    p = Problem(room, lms200, ranges, pose)
    with_check = TurningFunctionPlusMatcher().score(p, pose)
    without = TurningFunctionPlusMatcher(beam_check=False).score(p, pose)
    assert without < 1e-6 < with_check
