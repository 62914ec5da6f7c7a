"""``cartographer-local``: Cartographer's local matcher against the map, a labelled condition
(Cartographer never matches scan-to-map; its rotation_weight 40 is meant for an IMU heading; the
whole localization loop is ``cartographer``): ``LocalTrajectoryBuilder2D::ScanMatch`` of one scan
against the map's probability grid, from the tracker's prediction.

Stages, each a port of Cartographer's source (values: ``trajectory_builder_2d.lua``; the detail,
the sources and the departures: ``docs/baselines/cartographer-local.md``):

* **Filters** (:mod:`._filters`): the range cut, the 0.025 m voxel filter and the adaptive voxel
  filter choose the points both matchers read.
* **Real-time correlative scan matcher** (:mod:`._csm`), only with
  ``use_online_correlative_scan_matching`` (off as shipped; ``cartographer-local-csm`` turns it
  on as cartographer_ros's ``revo_lds.lua`` does): its best candidate is the Ceres matcher's start.
* **Ceres scan matcher** (``ceres_scan_matcher_2d.cc``): residuals
  ``occupied_space_weight/√N · (1 − P)`` at every point (P bicubic over the grid, :mod:`._grid`),
  ``translation_weight · (x − x_pred, y − y_pred)`` towards the *prediction's* position and
  ``rotation_weight · (θ − θ_start)`` towards the start's heading; solved by
  ``scipy.optimize.least_squares`` (Levenberg–Marquardt) with Ceres' default tolerances and at
  most ``max_num_iterations`` iterations.

The pose extrapolator keeps no state this port needs: with odometry at every scan its prediction
is the last estimate composed with the odometry increment, which is the guess
:class:`~tfloc.core.tracker.LocalTracker` gives; it has no rule for an odometry stall or jump.
So this is a single-scan matcher run along a sequence. It trusts its guess (the priors pull
towards it): it is meant for sequences (``kind`` tracker), not for the single-scan protocol.

**Amortised per map** (``prepare``): the probability grid. **Per scan**: the filters, the search
and the solve. ``score(problem, pose)``: the occupied-space part of Ceres' cost at ``pose``,
½·w²·mean((1 − P)²) (lower is better).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tfloc.core.params import Configured
from tfloc.core.pose import Pose
from tfloc.core.problem import NO_ANSWER, Estimate, Problem
from tfloc.core.traits import Confidence

from . import _ceres, _csm
from ._filters import matched_points
from ._grid import MIN_PROBABILITY, ProbabilityGrid, cost_at, probability_grid


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`CartographerLocalMatcher`: ``TRAJECTORY_BUILDER_2D``'s names and
    shipped values (``configuration_files/trajectory_builder_2d.lua``); metres, degrees where named."""

    RULES: ClassVar[dict] = {
        "> 0": ("voxel_filter_size", "adaptive_max_length", "occupied_space_weight", "translation_weight",
                "rotation_weight"),
        ">= 0": ("min_range", "max_range", "adaptive_min_num_points", "adaptive_max_range",
                 "linear_search_window", "angular_search_window_deg", "translation_delta_cost_weight",
                 "rotation_delta_cost_weight"),
        ">= 1": ("max_num_iterations",),
        "(0, 1)": ("occupied_probability",)}

    min_range: float = 0.0  #: returns nearer than this are dropped (m)
    max_range: float = 30.0  #: returns farther than this are misses, never matched (m)
    voxel_filter_size: float = 0.025  #: voxel filter's edge (m)
    adaptive_max_length: float = 0.5  #: adaptive_voxel_filter.max_length (m)
    adaptive_min_num_points: int = 200  #: adaptive_voxel_filter.min_num_points
    adaptive_max_range: float = 50.0  #: adaptive_voxel_filter.max_range (m)
    use_online_correlative_scan_matching: bool = False  #: run the real-time CSM before Ceres
    linear_search_window: float = 0.1  #: real-time CSM: ± this in x and y (m)
    angular_search_window_deg: float = 20.0  #: real-time CSM: ± this in heading (degrees)
    translation_delta_cost_weight: float = 0.1  #: real-time CSM: weight of the shift (1/m)
    rotation_delta_cost_weight: float = 0.1  #: real-time CSM: weight of the turn (1/rad)
    occupied_space_weight: float = 1.0  #: Ceres: weight of the occupied-space residuals
    translation_weight: float = 10.0  #: Ceres: weight of the pull towards the prediction (1/m)
    rotation_weight: float = 40.0  #: Ceres: weight of the pull towards the start's heading (1/rad)
    max_num_iterations: int = 20  #: Ceres: ceres_solver_options.max_num_iterations
    occupied_probability: float = 0.9  #: P of a cell the map calls occupied (kMaxProbability)


class CartographerLocalMatcher(Configured):
    """Cartographer's local scan matching against the map (see the module docstring)."""

    name = "cartographer-local"
    METHOD = "cartographer"  # (tfloc.core.traits)
    CONFIDENCE = Confidence("final_cost", False, "the Ceres scan matcher's final cost")
    kind = "tracker"  # (core.matcher.TRACKER: it pulls towards its guess; meant for sequences)
    CONFIG = Config

    def _grid(self, problem: Problem) -> ProbabilityGrid:
        return probability_grid(problem.map, self.config.occupied_probability)

    def _points(self, problem: Problem) -> np.ndarray:
        c = self.config
        return matched_points(problem.points, min_range=c.min_range, max_range=c.max_range,
                              voxel_size=c.voxel_filter_size, max_length=c.adaptive_max_length,
                              min_num_points=c.adaptive_min_num_points,
                              adaptive_max_range=c.adaptive_max_range)

    def prepare(self, problem: Problem) -> None:
        """Build the probability grid (once per map; untimed by the harness)."""
        self._grid(problem)

    def localize(self, problem: Problem) -> Estimate:
        """Filters, the optional real-time CSM, then the Ceres matcher, from ``problem.initial``."""
        c = self.config
        points = self._points(problem)
        pred = problem.initial
        if len(points) == 0:  # Cartographer drops the scan ("Dropped empty horizontal range data")
            return Estimate(pred, False, info={"status": NO_ANSWER, "reason": "no return within range"})
        grid = self._grid(problem)
        start, info = pred, {"points": int(len(points))}
        if c.use_online_correlative_scan_matching:
            start, score, n = _csm.match(grid, points, pred, c.linear_search_window,
                                         math.radians(c.angular_search_window_deg),
                                         c.translation_delta_cost_weight, c.rotation_delta_cost_weight)
            info.update(csm_score=score, csm_candidates=n)
        pose, sol = self._ceres(grid, points, pred, start)
        info.update(final_cost=float(sol.cost), solver_status=int(sol.status))
        return Estimate(pose, bool(sol.success), iterations=int(sol.nfev), info=info)

    def _ceres(self, grid: ProbabilityGrid, points: np.ndarray, pred: Pose, start: Pose):  # noqa: ANN202
        """``CeresScanMatcher2D::Match`` (:func:`._ceres.match`): the pose and scipy's result."""
        c = self.config
        return _ceres.match(grid, points, pred, start, c.occupied_space_weight, c.translation_weight,
                            c.rotation_weight, c.max_num_iterations)

    def score(self, problem: Problem, pose: Pose) -> float:
        """The occupied-space part of Ceres' cost at ``pose`` (module notes; lower is better)."""
        w = self.config.occupied_space_weight
        points = self._points(problem)
        if len(points) == 0:
            return 0.5 * w**2 * (1.0 - MIN_PROBABILITY) ** 2
        cost, _, _ = cost_at(self._grid(problem), pose.transform(points))
        return float(0.5 * w**2 * np.mean(cost**2))


REGISTRY = {"cartographer-local": {"class": "CartographerLocalMatcher", "docs": "baselines/cartographer-local.md", "files": ["baselines/cartographer/"], "summary": (
    "condition, \"Cartographer's local matcher against the map\" (Cartographer never matches "
    "scan-to-map; `rotation_weight` 40 is meant for an IMU heading): a port of Cartographer's"
    " 2D local scan matching against the map's probability grid (its voxel and adaptive voxel"
    " filters, the optional real-time correlative matcher, the Ceres matcher with bicubic "
    "interpolation and its priors towards the prediction), `trajectory_builder_2d.lua`'s "
    "values; meant for sequences (it pulls towards its guess); preset "
    "`cartographer-local-csm` turns the online correlative matcher on as cartographer_ros's "
    "`revo_lds.lua` ([docs/baselines/cartographer-local.md](baselines/cartographer-local.md))")}}
