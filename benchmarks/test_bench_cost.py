"""One ``tf`` cost evaluation (virtual scan, corners, turning function, matching) and the real
scan's turning function, with the paper's defaults, on the office map."""

from __future__ import annotations

import numpy as np
import pytest

from tfloc.core.pose import Pose
from tfloc.core.problem import Problem
from tfloc.paper.matcher import TfConfig, TurningFunctionMatcher, _Cost
from tfloc.paper.shape import scan_turning_function


@pytest.fixture(scope="module")
def problem(office, lms200, office_pose):
    initial = Pose(office_pose.x + 0.3, office_pose.y - 0.2, office_pose.theta + np.radians(3))
    return Problem(office, lms200, office.raycast(office_pose, lms200), initial)


def test_scan_turning_function(benchmark, problem):
    scan_turning_function(problem.ranges, problem.laser, TfConfig().shape)  # warm-up (JIT)
    tf = benchmark(scan_turning_function, problem.ranges, problem.laser, TfConfig())
    assert tf is not None and tf.n_edges >= 3


def test_cost_one_pose(benchmark, problem):
    """``_Cost.errors`` at one pose; target ≤ 300 µs (ideally ≤ 100 µs) median."""
    cfg = TfConfig()
    cost = _Cost(problem, cfg, scan_turning_function(problem.ranges, problem.laser, cfg.shape))
    pose = problem.initial.as_array()[None, :]
    cost.errors(pose)  # warm-up (JIT)
    errs, rots = benchmark(cost.errors, pose)
    assert errs.shape == (1,) and errs[0] < cfg.penalty


def test_cost_seven_orientations(benchmark, problem):
    """Alg. 5's Function1 batch: seven orientations at one position (one batched raycast)."""
    cfg = TfConfig()
    cost = _Cost(problem, cfg, scan_turning_function(problem.ranges, problem.laser, cfg.shape))
    p = problem.initial
    th = p.theta + np.radians(np.arange(-3, 4))
    poses = np.column_stack((np.full(7, p.x), np.full(7, p.y), th))
    cost.errors(poses)  # warm-up (JIT)
    errs, _ = benchmark(cost.errors, poses)
    assert (errs < cfg.penalty).all()


def test_tf_localize_one_scan(benchmark, problem):
    """A whole ``tf`` localization (Alg. 5 with outer iterations) of one office scan."""
    matcher = TurningFunctionMatcher()
    matcher.localize(problem)  # warm-up (JIT)
    est = benchmark.pedantic(matcher.localize, args=(problem,), rounds=5, iterations=1)
    assert est.evaluations > 0
    benchmark.extra_info["evaluations"] = est.evaluations
