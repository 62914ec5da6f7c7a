"""Cartographer's ``RealTimeCorrelativeScanMatcher2D`` (``real_time_correlative_scan_matcher_2d.cc``,
``correlative_scan_matcher_2d.cc``): an exhaustive search about the prediction at the grid's
resolution, the online stage before the Ceres matcher when ``use_online_correlative_scan_matching``
is on.

* The scan is turned to the prediction's heading, then to every heading of the window: ±``angular``
  in steps of (1 − 10⁻³)·acos(1 − r²/(2·d²)) (r the grid resolution, d the farthest point, at
  least 3 r: a step moves the farthest point by under a cell), ``ceil(angular / step)`` each side.
* Each turned scan is placed at the prediction's position and discretised to cells; candidates
  shift it by every whole number of cells within ±``ceil(linear / r)`` in x and y.
* A candidate's score is the mean probability of the cells its points fall in (off the grid:
  ``kMinProbability``), times exp(−(‖(x, y)‖·``translation_delta_cost_weight`` +
  |θ|·``rotation_delta_cost_weight``)²) of its offset from the prediction (metres, radians).
* The best candidate is the pose the Ceres matcher starts from (between exactly equal scores the
  first in heading, x, y order; Cartographer orders its shifts along its own cell axes).

Metres, radians; ``grid`` is a :class:`~._grid.ProbabilityGrid`.
"""

from __future__ import annotations

import math

import numpy as np

from tfloc.core.pose import Pose, wrap_angle

from ._grid import ProbabilityGrid


def angular_step(points: np.ndarray, resolution: float) -> float:
    """``SearchParameters``' angular step for the farthest of ``points`` (radians)."""
    far = max(3.0 * resolution, float(np.max(np.hypot(points[:, 0], points[:, 1]), initial=0.0)))
    return (1.0 - 1e-3) * math.acos(1.0 - resolution**2 / (2.0 * far**2))


def match(grid: ProbabilityGrid, points: np.ndarray, prediction: Pose, linear_window: float,
          angular_window: float, translation_weight: float, rotation_weight: float
          ) -> tuple[Pose, float, int]:
    """The best candidate pose about ``prediction`` for robot-frame ``points`` ``(N, 2)``, its
    score and the number of candidates scored."""
    r = grid.resolution
    step = angular_step(points, r)
    n_ang = int(math.ceil(angular_window / step))
    n_lin = int(math.ceil(linear_window / r))
    deltas = step * np.arange(-n_ang, n_ang + 1)
    thetas = prediction.theta + deltas
    c, s = np.cos(thetas)[:, None], np.sin(thetas)[:, None]
    wx = prediction.x + c * points[:, 0] - s * points[:, 1]  # (K, N)
    wy = prediction.y + s * points[:, 0] + c * points[:, 1]
    ci, cj = grid.cells(np.stack((wx, wy), axis=-1))
    offsets = np.arange(-n_lin, n_lin + 1)
    # scores[k, a, b]: heading k, shift a cells in x, b cells in y
    scores = np.empty((len(deltas), len(offsets), len(offsets)))
    for a, dx in enumerate(offsets):
        for b, dy in enumerate(offsets):
            scores[:, a, b] = grid.probability_at_cells(ci + dx, cj + dy).mean(axis=1)
    shift = r * offsets
    penalty = np.exp(-(np.hypot(shift[:, None], shift[None, :])[None, :, :] * translation_weight
                       + np.abs(deltas)[:, None, None] * rotation_weight) ** 2)
    scores *= penalty
    k, a, b = np.unravel_index(int(np.argmax(scores)), scores.shape)
    best = Pose(prediction.x + shift[a], prediction.y + shift[b], float(wrap_angle(thetas[k])))
    return best, float(scores[k, a, b]), int(scores.size)
