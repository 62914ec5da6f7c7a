"""Err (Eq. 13, or the L1 area) of ``tf`` on a grid of positions around a pose, for figures of the
objective around the true pose and for counting its basins.

Each grid point is a virtual scan at that position with the heading held at the centre pose's,
matched against the problem's real scan exactly as one orientation of ``tf``'s cost evaluation
(the best starting vertex and rotation offset of the turning functions, no seven-orientation
search). Positions that are not free space, or whose scan polygon is degenerate, are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tfloc.core.pose import Pose
from tfloc.core.problem import Problem

from .matcher import TfConfig, _Cost
from .shape import scan_turning_function


@dataclass(frozen=True, eq=False)
class Landscape:
    """Err on a grid: ``err[i, j]`` at ``(xs[j], ys[i])`` (metres), heading ``theta`` (radians).

    Err is in radians (L2) or radians × unit arc length (L1), NaN where undefined."""

    xs: np.ndarray
    ys: np.ndarray
    theta: float
    err: np.ndarray

    def distance_to(self, x: float, y: float) -> np.ndarray:
        """Distance (metres) of every grid point to ``(x, y)``, shaped like ``err``."""
        return np.hypot(self.xs[None, :] - x, self.ys[:, None] - y)


#: the grid the report draws: ±3 m at 5 cm around the truth
HALF_WIDTH_M = 3.0
GRID = 121


@dataclass(frozen=True)
class LandscapeStats:
    """What one scan's landscape shows (distances in metres): the initial guess's and the
    answer's distance from the truth, the grid's global minimum's, its local minima, and the rank
    correlation of Err with the distance to the truth beyond 1 m."""

    dataset: str
    scan_id: str
    init_dist_m: float
    answer_dist_m: float
    global_min_dist_m: float
    minima: int
    far_rank_correlation: float


@dataclass(frozen=True, eq=False)
class LandscapePanel:
    """One scan's landscape with the poses drawn on it (the truth, the guess, ``tf``'s answer)."""

    land: Landscape
    truth: Pose
    initial: Pose
    answer: Pose
    stats: LandscapeStats


def err_landscape(problem: Problem, centre: Pose, half_width_m: float = 1.0, n: int = 41,
                  config: TfConfig | None = None) -> Landscape:
    """Err of ``tf`` (under ``config``) on an ``n × n`` grid of positions spanning ±``half_width_m``
    around ``centre``, all at ``centre.theta``. Raises ``ValueError`` if the real scan's polygon
    is degenerate. ``config`` defaults to the literal ``TfConfig()``."""
    config = config or TfConfig()
    real = scan_turning_function(problem.ranges, problem.laser, config.shape)
    if real is None:
        raise ValueError("the real scan's polygon has fewer than 3 edges")
    xs = centre.x + np.linspace(-half_width_m, half_width_m, n)
    ys = centre.y + np.linspace(-half_width_m, half_width_m, n)
    gx, gy = np.meshgrid(xs, ys)
    poses = np.column_stack((gx.ravel(), gy.ravel(), np.full(gx.size, centre.theta)))
    errs, _ = _Cost(problem, config, real).errors(poses)
    err = np.where(errs >= config.penalty, np.nan, errs).reshape(n, n)
    return Landscape(xs, ys, float(centre.theta), err)


def local_minima(err: np.ndarray) -> np.ndarray:
    """Mask of the grid's strict-or-equal local minima: finite cells no greater than any finite
    8-neighbour (NaN cells never count and do not constrain). Their number counts the basins a
    local search can end in."""
    e = np.where(np.isfinite(err), err, np.inf)
    p = np.pad(e, 1, constant_values=np.inf)
    h, w = e.shape
    mask = np.isfinite(e)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di or dj:
                mask &= e <= p[1 + di:1 + di + h, 1 + dj:1 + dj + w]
    return mask
