"""Cartographer's ``CeresScanMatcher2D::Match`` (``ceres_scan_matcher_2d.cc``,
``occupied_space_cost_function_2d.cc``, ``translation_delta_cost_functor_2d.h``,
``rotation_delta_cost_functor_2d.h``): residuals ``occupied_space_weight/√N · (1 − P)`` at every
point (P bicubic over the grid, :mod:`._grid`), ``translation_weight · (x − x_target, y − y_target)``
towards the *target's* position and ``rotation_weight · (θ − θ_start)`` towards the start's
heading; solved by ``scipy.optimize.least_squares`` (Levenberg–Marquardt, analytic Jacobian) with
Ceres' default tolerances and at most ``max_num_iterations`` + 1 evaluations. Shared by the local
trajectory builder (target = the prediction) and the constraint builder (target = the branch and
bound's answer). Metres, radians.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares

from tfloc.core.pose import Pose, wrap_angle

from ._grid import ProbabilityGrid, cost_at


def match(grid: ProbabilityGrid, points: np.ndarray, target: Pose, start: Pose, occupied_space_weight: float,
          translation_weight: float, rotation_weight: float, max_num_iterations: int):  # noqa: ANN201
    """The refined pose of robot-frame ``points`` ``(N ≥ 1, 2)`` from ``start``, and scipy's result."""
    scale = occupied_space_weight / math.sqrt(len(points))
    px, py = points[:, 0], points[:, 1]
    memo: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def evaluate(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = v.tobytes()
        if key not in memo:
            memo.clear()
            cos, sin = math.cos(v[2]), math.sin(v[2])
            xy = np.column_stack((v[0] + cos * px - sin * py, v[1] + sin * px + cos * py))
            cost, gx, gy = cost_at(grid, xy)
            r = np.concatenate((scale * cost, translation_weight * (v[:2] - (target.x, target.y)),
                                [rotation_weight * (v[2] - start.theta)]))
            jac = np.zeros((len(r), 3))
            jac[:len(px), 0] = scale * gx
            jac[:len(px), 1] = scale * gy
            jac[:len(px), 2] = scale * (gx * (-sin * px - cos * py) + gy * (cos * px - sin * py))
            jac[len(px), 0] = jac[len(px) + 1, 1] = translation_weight
            jac[len(px) + 2, 2] = rotation_weight
            memo[key] = (r, jac)
        return memo[key]

    sol = least_squares(lambda v: evaluate(v)[0], start.as_array(), jac=lambda v: evaluate(v)[1],
                        method="lm", ftol=1e-6, xtol=1e-8, gtol=1e-10, max_nfev=max_num_iterations + 1)
    v = sol.x
    return Pose(float(v[0]), float(v[1]), float(wrap_angle(v[2]))), sol
