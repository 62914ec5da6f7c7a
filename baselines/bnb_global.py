"""``bnb-global``: Cartographer's branch-and-bound scan matcher over the whole map and all headings.

Hess, Kohler, Rapp, Andor, "Real-Time Loop Closure in 2D LIDAR SLAM", ICRA 2016, Sec. V
(Cartographer's ``MatchFullSubmap``), implemented as published (PyPI has no Cartographer bindings)
with compiled kernels (:mod:`tfloc.baselines._bnb_kernels`) and Cartographer's defaults. Choices
and why (the detail: ``docs/baselines/bnb-global.md``; results: ``docs/global.md``):

* **Probability grid**: our maps are not Cartographer submaps, whose insertion smears the walls,
  so the grid is the map blurred through its distance field, ``p = 0.1 + 0.8·exp(−d²/2σ²)``
  (Cartographer's probability range), stored as uint8 with its precomputed grids.
* **Search**: every heading (Cartographer's angular step, from the farthest return) and every cell
  whose centre lies within the map's bounds (a map localizer never needs a robot off the map);
  depth-first branch and bound, cut at ``min_score`` until ``hypotheses`` distinct answers are
  held, then at the last one's score, so that the best few answers come out, not only the best.
* As Cartographer's constraint builder: the scan through its **adaptive voxel filter** first (it
  bounds the per-candidate cost on long-range scans), each hypothesis **refined** by its Ceres
  scan-matcher residuals (here ``scipy.optimize.least_squares``) and re-ranked; no pose above
  ``min_score`` is no answer; a local problem is searched within its window about the guess.

**Amortised per map** (``prepare``): the probability grid and its precomputed grids.
**Per scan**: the rotated, discretised scans, the branch and bound, the refinement.

``score(problem, pose)``: ``1 −`` the mean interpolated grid probability of the scan's
(voxel-filtered) returns at ``pose``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.ndimage import map_coordinates
from scipy.optimize import least_squares

from tfloc.core.params import Configured
from tfloc.core.pose import Pose, wrap_angle
from tfloc.core.problem import Estimate, Problem
from tfloc.errors import ParameterError
from tfloc.maps.cache import cached
from tfloc.maps.fields import distance_field

from ._bnb_kernels import angular_step, branch_and_bound, discretize, pyramid

P_MIN, P_MAX = 0.1, 0.9  # Cartographer's probability range (kMinProbability, kMaxProbability)
MAX_DEPTH = 12


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`BranchAndBoundGlobalMatcher` (metres, degrees where named)."""

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("resolution", "sigma", "linear_search_window", "angular_search_window_deg",
                "distinct_m", "distinct_deg", "occupied_space_weight", "voxel_max_length"),
        ">= 0": ("translation_weight", "rotation_weight"),
        "[0, 1]": ("min_score",),
        ">= 1": ("branch_and_bound_depth", "hypotheses", "refine_max_evals", "voxel_min_num_points")}

    resolution: float = 0.05  #: cell size of the probability grid (metres)
    sigma: float = 0.05  #: blur of the grid's walls, p = 0.1 + 0.8·exp(−d²/2σ²) (metres)
    branch_and_bound_depth: int = 7  #: levels of precomputed grids
    min_score: float = 0.6  #: score an answer must exceed (mean probability, 0–1)
    hypotheses: int = 5  #: distinct answers kept, best first
    distinct_m: float = 0.5  #: answers closer than this are one answer (metres) ...
    distinct_deg: float = 10.0  #: ... and closer than this in heading (degrees)
    linear_search_window: float = 7.0  #: local problems: ± this about the guess (metres)
    angular_search_window_deg: float = 30.0  #: local problems: ± this about the guess (degrees)
    refine: bool = True  #: least-squares refinement of each hypothesis
    occupied_space_weight: float = 20.0  #: refinement: occupied-space weight w (w/√N)
    translation_weight: float = 10.0  #: refinement: weight toward the search's x, y (1/m)
    rotation_weight: float = 1.0  #: refinement: weight toward its heading (1/rad)
    refine_max_evals: int = 50  #: refinement: least_squares' max_nfev
    voxel_filter: bool = True  #: thin the scan by the adaptive voxel filter first
    voxel_max_length: float = 0.9  #: the filter's coarsest voxel edge (metres)
    voxel_min_num_points: int = 100  #: the filter keeps at least this many returns


@dataclass(frozen=True, eq=False)
class ProbabilityGrid:
    """A map's probability grid and its precomputed grids.

    Attributes:
        prob: ``(H, W)`` float32 probability per cell (row = y, column = x).
        grids: ``(depth, H + 2·pad, W + 2·pad)`` uint8 precomputed grids (level 0 = ``prob``).
        pad: margin of ``grids``, cells.
        origin: world ``(x, y)`` of the centre of cell ``[0, 0]``, metres.
        resolution: cell size, metres.
        x_range, y_range: the cells (inclusive) whose centres lie within the map's bounds: where
            the robot is searched in a global problem.
    """

    prob: np.ndarray
    grids: np.ndarray
    pad: int
    origin: tuple[float, float]
    resolution: float
    x_range: tuple[int, int]
    y_range: tuple[int, int]

    @property
    def nbytes(self) -> int:
        """Memory of the grids (the precomputed stack and the float grid), bytes."""
        return int(self.grids.nbytes + self.prob.nbytes)

    def cell(self, x: float, y: float) -> tuple[int, int]:
        """The cell whose centre is nearest to world ``(x, y)``."""
        return (int(round((x - self.origin[0]) / self.resolution)),
                int(round((y - self.origin[1]) / self.resolution)))

    def world(self, cx: np.ndarray, cy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World coordinates (metres) of cell centres."""
        return self.origin[0] + cx * self.resolution, self.origin[1] + cy * self.resolution

    def probability_at(self, xy: np.ndarray) -> np.ndarray:
        """Bilinearly interpolated probability at world points ``(N, 2)`` (``P_MIN`` off the grid)."""
        g = (np.asarray(xy, dtype=float) - self.origin) / self.resolution
        return map_coordinates(self.prob, (g[:, 1], g[:, 0]), order=1, mode="constant", cval=P_MIN)


def voxel_filter(points: np.ndarray, edge: float) -> np.ndarray:
    """The first of ``points`` ``(N, 2)`` (metres) in each square voxel of ``edge`` metres, in order."""
    keys = np.floor(points / edge).astype(np.int64)
    _, first = np.unique(keys, axis=0, return_index=True)
    return points[np.sort(first)]


def adaptive_voxel_filter(points: np.ndarray, max_length: float, min_num_points: int) -> np.ndarray:
    """Cartographer's ``AdaptiveVoxelFilter``: ``points`` filtered with the largest voxel edge
    (≤ ``max_length``, found by halving then a binary search to 10 %) that keeps at least
    ``min_num_points`` of them; all of them when there are no more than that, or when even an edge of
    ``max_length``/100 keeps too few."""
    if len(points) <= min_num_points:
        return points
    result = voxel_filter(points, max_length)
    if len(result) >= min_num_points:
        return result
    high = max_length
    while high > 1e-2 * max_length:
        low = high / 2.0
        result = voxel_filter(points, low)
        if len(result) >= min_num_points:
            while (high - low) / low > 1e-1:
                mid = 0.5 * (low + high)
                cand = voxel_filter(points, mid)
                if len(cand) >= min_num_points:
                    low, result = mid, cand
                else:
                    high = mid
            return result
        high /= 2.0
    return result


def build_probability_grid(map_: object, resolution: float, sigma: float, depth: int) -> ProbabilityGrid:
    """The likelihood-blurred probability grid of ``map_`` and its ``depth`` precomputed grids."""
    f = distance_field(map_, resolution, max(1.0, 6.0 * sigma), 0.0)
    prob = (P_MIN + (P_MAX - P_MIN) * np.exp(-0.5 * (f.distance.astype(np.float64) / sigma) ** 2))
    values = np.rint((prob - P_MIN) * (255.0 / (P_MAX - P_MIN))).astype(np.uint8)
    grids = pyramid(values, depth)
    h, w = values.shape
    x0, y0, x1, y1 = map_.bounds
    ox, oy = f.origin
    xr = (max(0, math.ceil((x0 - ox) / resolution - 1e-9)), min(w - 1, math.floor((x1 - ox) / resolution + 1e-9)))
    yr = (max(0, math.ceil((y0 - oy) / resolution - 1e-9)), min(h - 1, math.floor((y1 - oy) / resolution + 1e-9)))
    return ProbabilityGrid(prob.astype(np.float32), grids, (1 << (depth - 1)) - 1, f.origin,
                           float(resolution), xr, yr)


def probability_grid(map_: object, resolution: float, sigma: float, depth: int) -> ProbabilityGrid:
    """:func:`build_probability_grid`, once per map and parameters (:mod:`tfloc.maps.cache`)."""
    key = ("bnb-grid", round(resolution, 9), round(sigma, 9), int(depth))
    return cached(map_, key, lambda: build_probability_grid(map_, resolution, sigma, depth))


class BranchAndBoundGlobalMatcher(Configured):
    """Cartographer's fast correlative scan matcher over the whole map (see the module docstring)."""

    name = "bnb-global"
    solves_global = True
    CONFIG = Config

    def __init__(self, config: Config | None = None, **overrides) -> None:
        super().__init__(config, **overrides)
        c = self.config
        if c.branch_and_bound_depth > MAX_DEPTH:
            raise ParameterError(f"branch_and_bound_depth must be ≤ {MAX_DEPTH}, got "
                                 f"{c.branch_and_bound_depth}", ("branch_and_bound_depth",))
        if c.angular_search_window_deg > 180.0:
            raise ParameterError(f"angular_search_window_deg must be ≤ 180, got "
                                 f"{c.angular_search_window_deg}", ("angular_search_window_deg",))

    def _grid(self, problem: Problem) -> ProbabilityGrid:
        c = self.config
        return probability_grid(problem.map, c.resolution, c.sigma, c.branch_and_bound_depth)

    def prepare(self, problem: Problem) -> None:
        """Build the probability grid and its precomputed grids (once per map; untimed)."""
        self._grid(problem)

    def _points(self, problem: Problem) -> np.ndarray:
        """The scan's returns (sensor frame, metres), through the adaptive voxel filter if enabled."""
        c = self.config
        pts = problem.points
        return adaptive_voxel_filter(pts, c.voxel_max_length, c.voxel_min_num_points) if c.voxel_filter else pts

    def _window(self, grid: ProbabilityGrid, problem: Problem, step: float):
        """Headings (radians) and the translation window (cells, inclusive) to search."""
        c = self.config
        if problem.is_global:
            n = math.ceil(2.0 * math.pi / step)
            thetas = -math.pi + (2.0 * math.pi / n) * np.arange(n)
            return thetas, grid.x_range, grid.y_range
        init = problem.initial
        na = math.ceil(math.radians(c.angular_search_window_deg) / step)
        thetas = init.theta + step * np.arange(-na, na + 1)
        cx, cy = grid.cell(init.x, init.y)
        nl = math.ceil(c.linear_search_window / c.resolution)
        xr = (max(grid.x_range[0], cx - nl), min(grid.x_range[1], cx + nl))
        yr = (max(grid.y_range[0], cy - nl), min(grid.y_range[1], cy + nl))
        return thetas, xr, yr

    def localize(self, problem: Problem) -> Estimate:
        """Branch and bound over the whole map (global) or the window about the guess, then refine."""
        c = self.config
        grid = self._grid(problem)
        pts = self._points(problem)
        step = angular_step(float(np.max(np.hypot(pts[:, 0], pts[:, 1]))), c.resolution)
        thetas, xr, yr = self._window(grid, problem, step)
        if xr[0] > xr[1] or yr[0] > yr[1]:
            return Estimate(Pose(math.nan, math.nan, math.nan), False, info={"status": "no-answer"})
        offsets = discretize(pts, thetas, c.resolution)
        scale = 255.0 / (P_MAX - P_MIN)
        min_sum = (c.min_score - P_MIN) * scale * len(pts)
        rot_steps = int(math.floor(math.radians(c.distinct_deg) / (2.0 * math.pi / len(thetas))
                                   if problem.is_global else math.radians(c.distinct_deg) / step))
        hk, hx, hy, hs, count, scored = branch_and_bound(
            grid.grids, grid.pad, offsets, xr[0], xr[1], yr[0], yr[1], float(min_sum),
            int(c.hypotheses), c.distinct_m / c.resolution, rot_steps)
        info = {"headings": int(len(thetas)), "angular_step_deg": math.degrees(step), "points": int(len(pts)),
                "candidates_scored": int(scored), "found": int(count)}
        if count == 0:
            info["status"] = "no-answer"
            return Estimate(Pose(math.nan, math.nan, math.nan), False, iterations=0,
                            evaluations=int(scored), info=info)
        wx, wy = grid.world(hx[:count].astype(float), hy[:count].astype(float))
        poses = [Pose(float(wx[j]), float(wy[j]), float(wrap_angle(thetas[hk[j]]))) for j in range(count)]
        bnb_scores = P_MIN + hs[:count] / (scale * len(pts))
        nfev = 0
        if c.refine:
            refined = [self._refine(grid, pts, p) for p in poses]
            nfev = sum(n for _, n in refined)
            poses = [p for p, _ in refined]
        own = np.array([self._score(grid, pts, p) for p in poses])
        order = np.argsort(own, kind="stable")
        poses = [poses[j] for j in order]
        info.update({"bnb_score": float(bnb_scores[order[0]]), "score": float(1.0 - own[order[0]]),
                     "refine_evals": int(nfev)})
        return Estimate(poses[0], True, iterations=int(count), evaluations=int(scored + nfev),
                        info=info, hypotheses=tuple(poses))

    def _refine(self, grid: ProbabilityGrid, pts: np.ndarray, start: Pose) -> tuple[Pose, int]:
        """Cartographer's Ceres refinement: occupied-space residuals on the interpolated grid plus
        translation and rotation residuals toward ``start`` (scipy ``least_squares``)."""
        c = self.config
        w_occ = c.occupied_space_weight / math.sqrt(len(pts))
        x0 = start.as_array()

        def residuals(v: np.ndarray) -> np.ndarray:
            p = grid.probability_at(Pose(v[0], v[1], v[2]).transform(pts))
            return np.concatenate((w_occ * (1.0 - p), [c.translation_weight * (v[0] - x0[0]),
                                                       c.translation_weight * (v[1] - x0[1]),
                                                       c.rotation_weight * (v[2] - x0[2])]))

        sol = least_squares(residuals, x0, x_scale=np.array([0.01, 0.01, 0.002]),
                            diff_step=np.array([1e-4, 1e-4, 1e-4]), max_nfev=c.refine_max_evals,
                            method="trf")
        v = sol.x
        return Pose(float(v[0]), float(v[1]), float(wrap_angle(v[2]))), int(sol.nfev)

    @staticmethod
    def _score(grid: ProbabilityGrid, pts: np.ndarray, pose: Pose) -> float:
        return 1.0 - float(np.mean(grid.probability_at(pose.transform(pts))))

    def score(self, problem: Problem, pose: Pose) -> float:
        """``1 −`` the mean interpolated grid probability of the (filtered) returns at ``pose`` (lower is better)."""
        return self._score(self._grid(problem), self._points(problem), pose)


REGISTRY = {"bnb-global": {"class": "BranchAndBoundGlobalMatcher", "docs": "baselines/bnb-global.md", "files": ["baselines/_bnb_kernels.py"], "summary": (
    "Cartographer's branch-and-bound scan matcher (Hess et al. 2016, Sec. V) over the whole "
    "map and all headings: the reference for **global** problems (no initial guess; "
    "[docs/global.md](global.md))")}}
