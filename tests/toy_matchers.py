"""Toy matchers for harness tests (loaded as ``tests.toy_matchers:Class`` by worker processes)."""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.optimize import minimize

from tfloc.pose import Pose
from tfloc.problem import Estimate, Problem


def _mismatch(problem: Problem, pose: Pose) -> float:
    """Mean absolute range difference (m) between the real scan and the map raycast at ``pose``."""
    sim = problem.map.raycast(pose, problem.laser)
    ok = problem.laser.valid(problem.ranges) & problem.laser.valid(sim)
    return float(np.mean(np.abs(sim[ok] - problem.ranges[ok]))) if ok.any() else 1e9


class GridSearchMatcher:
    """Honest matcher: exhaustive search on a fine grid around the initial guess, then Nelder-Mead."""

    name = "grid"

    def __init__(self, radius: float = 0.3, step: float = 0.05):
        self.radius, self.step = radius, step

    def localize(self, problem: Problem) -> Estimate:
        f = lambda v: _mismatch(problem, Pose(*v))  # noqa: E731
        res = minimize(f, problem.initial.as_array(), method="Nelder-Mead",
                       options={"xatol": 1e-4, "fatol": 1e-6, "initial_simplex": None})
        return Estimate(Pose(*res.x), bool(res.success), int(res.nit), int(res.nfev))

    def score(self, problem: Problem, pose: Pose) -> float:
        return _mismatch(problem, pose)


class IdentityMatcher:
    """Returns the initial guess; its score is the scan mismatch (so it stops at a false optimum)."""

    name = "identity"

    def localize(self, problem: Problem) -> Estimate:
        return Estimate(problem.initial, True)

    def score(self, problem: Problem, pose: Pose) -> float:
        return _mismatch(problem, pose)


class FalseOptimumMatcher:
    """Objective with a known false optimum, for a dataset whose true position ``(tx, ty)`` is
    given as a parameter: f(p) = min(|p − t|², |p − t − (2, 0)|² + c) with c = −1 (``deep``: the
    false optimum is the global one, so answering it is ``ambiguous``) or c = +1 (a shallower
    false optimum: answering it is a ``local-optimum`` failure). It always answers the false one."""

    name = "false-optimum"

    def __init__(self, tx: float = 0.0, ty: float = 0.0, deep: bool = True):
        self.tx, self.ty, self.c = tx, ty, (-1.0 if deep else 1.0)

    def localize(self, problem: Problem) -> Estimate:
        return Estimate(Pose(self.tx + 2.0, self.ty, problem.initial.theta), True)

    def score(self, problem: Problem, pose: Pose) -> float:
        d_true = (pose.x - self.tx) ** 2 + (pose.y - self.ty) ** 2
        d_false = (pose.x - self.tx - 2.0) ** 2 + (pose.y - self.ty) ** 2
        return min(d_true, d_false + self.c)


class RaisingMatcher:
    name = "raising"

    def localize(self, problem: Problem) -> Estimate:
        raise RuntimeError("boom\nsecond line")

    def score(self, problem: Problem, pose: Pose) -> float:
        return 0.0


class HangingMatcher:
    name = "hanging"

    def localize(self, problem: Problem) -> Estimate:
        time.sleep(3600)
        return Estimate(problem.initial, False)

    def score(self, problem: Problem, pose: Pose) -> float:
        return 0.0


class SlowMatcher:
    """Returns the initial guess after ``delay`` seconds (for the resume test)."""

    name = "slow"

    def __init__(self, delay: float = 0.2):
        self.delay = delay

    def localize(self, problem: Problem) -> Estimate:
        time.sleep(self.delay)
        return Estimate(problem.initial, True)

    def score(self, problem: Problem, pose: Pose) -> float:
        return math.hypot(pose.x, pose.y)
