"""The ambiguous readings of the paper as switches of ``TfConfig``: literal defaults, the L1/L2
measures on hand-made turning functions, the path resampling, and the outer loop's heading
clamp and keep-best choice."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _tf_oracles import match_l1, resample_path, step_by_step_tf

import tfloc.paper.matcher
from tfloc import Pose, Problem
from tfloc.errors import MatcherError
from tfloc.paper.corners import resample
from tfloc.paper.matcher import TfConfig, TurningFunctionMatcher
from tfloc.paper.turning import TurningFunction, match, turning_function

TRUE = Pose(3.0, 3.5, 0.4)


def step(breaks, angles) -> TurningFunction:
    return TurningFunction(np.asarray(breaks, dtype=float), np.asarray(angles, dtype=float))


def test_literal_defaults_are_pinned():
    c = TfConfig()
    assert (c.err_norm, c.resampling, c.spacing, c.window, c.simplex_size) == ("l2", "chord", 1.0, 1, 1.0)
    assert c.orientation_step == math.radians(1.0) and c.n_orientations == 7
    assert c.heading_clamp == math.inf and c.rotation_correction and not c.keep_best
    assert c.close_through_origin


@pytest.mark.parametrize("bad", [{"err_norm": "l3"}, {"resampling": "spline"}, {"spacing": 0.0},
                                 {"heading_clamp": 0.0}])
def test_bad_switch_values_are_one_line_errors(bad):
    with pytest.raises(MatcherError, match=next(iter(bad))):
        TfConfig(**bad)


def test_l1_and_l2_on_a_hand_made_pair():
    # Θ_R: 0 on [0, 1/4), 1 on [1/4, 1); Θ_V: 0 on [0, 1) (one piece, so a single shift).
    real, virtual = step([0, 0.25, 1], [0, 1]), step([0, 1], [0])
    # L2: best θ = mean of Θ_R − Θ_V = 3/4; Err² = ¼·(3/4)² + ¾·(1/4)² = 3/16.
    m2 = match(real, virtual)
    assert m2.rotation == pytest.approx(0.75) and m2.distance == pytest.approx(math.sqrt(3 / 16))
    # L1: best θ = weighted median = 1 (¾ of the length has difference 1); area = ¼·1 = ¼.
    # At the mean θ = 3/4 the area would be ¼·¾ + ¾·¼ = 3/8 > ¼.
    m1 = match_l1(real, virtual)
    assert m1.rotation == pytest.approx(1.0) and m1.distance == pytest.approx(0.25)


def test_l1_ties_take_the_midpoint_and_keep_the_area():
    # equal halves at differences 0 and 1: every θ in [0, 1] gives area ½; the midpoint is returned
    m1 = match_l1(step([0, 0.5, 1], [0, 1]), step([0, 1], [0]))
    assert m1.distance == pytest.approx(0.5) and m1.rotation == pytest.approx(0.5)


def test_l1_searches_the_starting_vertex():
    # the virtual quadrilateral started at its second vertex is the real one: area 0 at shift 1
    quad = np.array([[0, 0], [3, 0], [2, 1], [0, 2.0]])
    real = turning_function(np.roll(quad, -1, axis=0))
    m1 = match_l1(real, turning_function(quad))
    assert m1.distance == pytest.approx(0.0, abs=1e-12) and m1.shift == 1
    assert m1.rotation == pytest.approx(0.0, abs=1e-12)


def _area_brute(real, virtual, shift, theta, n=20000):
    s = (np.arange(n) + 0.5) / n
    start = virtual.breaks[shift]
    u = s + start
    wrapped = u >= 1.0
    tv = virtual(np.where(wrapped, u - 1.0, u)) + 2 * np.pi * wrapped
    return np.mean(np.abs(real(s) - tv - theta))


@pytest.mark.parametrize("seed", range(5))
def test_l1_is_the_minimal_area_over_shifts_and_rotations(seed):
    """Against a numerical integral: no shift and rotation on a grid beats match_l1's area."""
    rng = np.random.default_rng(seed)

    def poly(n):
        phi = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(0.5, 3.0, n)
        return turning_function(np.column_stack((r * np.cos(phi), r * np.sin(phi))))

    real, virtual = poly(6), poly(5)
    m1 = match_l1(real, virtual)
    at = min(_area_brute(real, virtual, m1.shift, m1.rotation + 2 * np.pi * j) for j in (-1, 0, 1))
    assert at == pytest.approx(m1.distance, abs=1e-3)   # the rotation is returned modulo 2π
    grid = np.linspace(-2 * np.pi, 2 * np.pi, 721)
    best = min(_area_brute(real, virtual, k, th, 2000) for k in range(virtual.n_edges) for th in grid)
    assert m1.distance <= best + 2e-3


def test_path_resampling_walks_the_path_not_chords():
    corner = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    # along the path: every 0.4 m of path length, so the point after (0.8, 0) is (1, 0.2)
    np.testing.assert_allclose(resample_path(corner, 0.4),
                               [[0, 0], [0.4, 0], [0.8, 0], [1, 0.2], [1, 0.6], [1, 1]], atol=1e-12)
    # the chord walk of Alg. 1's formula steps from (0.8, 0) straight towards (1, 1)
    chord = resample(corner, 0.4)
    assert np.hypot(*(chord[3] - chord[2])) == pytest.approx(0.4) and chord[3][0] < 1.0
    # on a straight line both readings agree
    line = np.column_stack((np.linspace(0, 3, 31), np.zeros(31)))
    np.testing.assert_allclose(resample_path(line, 0.5), resample(line, 0.5), atol=1e-12)


@pytest.mark.parametrize("overrides", [{"err_norm": "l1"}, {"resampling": "path"},
                                       {"close_through_origin": False, "spacing": 0.25}],
                         ids=["l1", "path", "direct"])
def test_fused_cost_equals_the_step_by_step_path(test_room, lms200, overrides, monkeypatch):
    ranges = test_room.raycast(TRUE, lms200) + np.random.default_rng(0).normal(0, 0.01, lms200.n_beams)
    problem = Problem(test_room, lms200, ranges, Pose(3.4, 3.2, 0.5))
    matcher = TurningFunctionMatcher(**overrides)
    fast = matcher.localize(problem)
    step_by_step_tf(monkeypatch)
    slow = matcher.localize(problem)
    assert fast.pose == slow.pose and fast.evaluations == slow.evaluations


def test_heading_clamp_bounds_the_change_from_the_initial_heading():
    free = TurningFunctionMatcher()
    clamped = TurningFunctionMatcher(heading_clamp=math.radians(15))
    # best orientation 0.1 rad, rotation offset −1.0 rad: unbounded heading 1.1 rad
    assert free.heading(0.1, -1.0, 0.0) == pytest.approx(1.1)
    assert clamped.heading(0.1, -1.0, 0.0) == pytest.approx(math.radians(15))
    assert clamped.heading(0.1, 1.0, 0.0) == pytest.approx(-math.radians(15))
    assert clamped.heading(0.1, 0.05, 0.0) == pytest.approx(0.05)          # inside: unchanged
    # across ±π: initial π − 0.05, unbounded π + 0.39 (a change of 0.44 rad), clamped to +15°
    assert clamped.heading(math.pi - 0.01, -0.4, math.pi - 0.05) == pytest.approx(
        math.pi - 0.05 + math.radians(15) - 2 * math.pi)
    assert TurningFunctionMatcher(rotation_correction=False).heading(0.1, -1.0, 0.0) == 0.1


def test_keep_best_returns_the_lowest_err_pose_not_the_last(test_room, lms200, monkeypatch):
    """A scripted outer loop: simplex ends at three positions whose Err is 0.5, 0.2, 0.4."""
    ends = iter([np.array([1.0, 1.0]), np.array([2.0, 2.0]), np.array([3.0, 3.0])])
    errs = {1.0: 0.5, 2.0: 0.2, 3.0: 0.4}
    step_by_step_tf(monkeypatch)  # the Python driver (the compiled one runs the same steps)
    monkeypatch.setattr(tfloc.paper.matcher, "simplex", lambda cost, pose, size, rng: (next(ends), 1))
    monkeypatch.setattr(tfloc.paper.matcher._Cost, "function1",
                        lambda self, xy, th: (errs.get(float(xy[0]), 0.9), th, 0.0))
    ranges = test_room.raycast(TRUE, lms200)
    problem = Problem(test_room, lms200, ranges, Pose(0.5, 0.5, 0.0))
    last = TurningFunctionMatcher(max_outer=3).localize(problem)
    assert (last.pose.x, last.info["err"]) == (3.0, 0.4)
    ends = iter([np.array([1.0, 1.0]), np.array([2.0, 2.0]), np.array([3.0, 3.0])])
    best = TurningFunctionMatcher(max_outer=3, keep_best=True).localize(problem)
    assert (best.pose.x, best.info["err"]) == (2.0, 0.2)
