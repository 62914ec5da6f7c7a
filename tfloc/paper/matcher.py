"""The paper's pose search: turning-function matching driven by a Nelder–Mead simplex.

Sec. 4.4, Eq. 13 and Algorithm 5. One *cost evaluation* simulates the virtual scan (VSD) at a
candidate pose, finds its ShortStraw corners (Algs. 1–3), builds its turning function (Alg. 4)
and matches it against the real scan's (Sec. 4.3). ``Function1(P, θ_v)`` of Alg. 5 checks seven
orientations around θ_v at position P (one batched virtual scan) and keeps the best.

Readings (the text is ambiguous or wrong; each choice is the one that works):

* **Scan polygon.** Alg. 4 needs a closed counter-clockwise polygon; a 180° scan is an open
  polyline. We close it through the sensor origin (the scan's visibility polygon), which is
  counter-clockwise and simple by construction; closing it directly from the last to the first
  corner can self-intersect. ``close_through_origin=False`` gives the direct closure.
* **No-return beams** are dropped and their neighbours joined (a dropout then changes the polygon
  by one short chord; clipping to max range would add a spurious arc).
* **Alg. 5's W** is "the point with 2nd maximum error", which for three points is NB; it is read
  as the worst point.
* **Alg. 5 has no shrink step**: it accepts a contraction even when it is no better than W. Then
  W creeps onto the midpoint of B and NB while B and NB never move, and the simplex never
  converges (observed: 60 iterations ending on one repeated point). We keep the paper's moves and
  add Nelder–Mead's shrink towards B only when the contracted point is not better than W. Alg. 5
  also has no convergence test; we stop when the simplex is smaller than ``xy_tol`` or after
  ``max_iterations``.
* **Function1(P, θ_v)** is a function of P only (θ_v is fixed while the simplex runs), so the
  re-evaluations of B, NB, W in each loop of Alg. 5 return the same values; they are cached.
* **Seven orientations**: θ_v + k·``orientation_step`` for k = −3…3 (the paper gives no step).
* **Outer iterations** (Eq. 2, Δθ = Σδθ_k): after a simplex run the pose becomes the best vertex,
  its heading the best of the seven corrected by the histogram's rotation offset (the
  orientation-difference estimate of Sec. 4.3); the virtual scan is re-simulated and the simplex
  restarts around it, its size halved each time, until Err ≤ ``err_threshold`` or the pose moves
  less than ``xy_tol``/``theta_tol``.
* **Initial simplex**: "three random points … covering the maximum position difference": the VP
  and two points ``simplex_size`` metres away at a seeded random direction, 60° apart.
* **Invalid candidates** (inside a wall/obstacle, off the map, fewer than 2 corners in the
  virtual scan) cost ``penalty`` instead of raising.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.params import Configured
from tfloc.core.pose import Pose, wrap_angle
from tfloc.core.problem import Estimate, Problem

from .corners import shortstraw
from .turning import TurningFunction, match, turning_function

_ORIGIN = np.zeros((1, 2))


@dataclass(frozen=True)
class TfConfig:
    """Parameters of the ``tf`` matcher; defaults follow the paper where it gives a value.

    Attributes:
        spacing: S of Alg. 1, resampling distance (metres). The paper writes S = 1 without a
            unit; see the module notes of :mod:`tfloc.paper.corners` and the README for the choice.
        window: w of Alg. 2 (the paper's w = 1; ShortStraw's authors use 3).
        straw_t: t of Alg. 2 (0.99).
        line_threshold: Is-Line threshold of Alg. 3 (0.95).
        close_through_origin: close the scan polygon through the sensor origin.
        n_orientations: orientations checked per simplex vertex (7).
        orientation_step: spacing of those orientations (radians).
        simplex_size: initial simplex size (metres); should cover the largest position offset.
        err_threshold: Eq. 13's threshold on Err (radians).
        xy_tol: simplex size (metres) and outer-iteration move below which the search stops.
        theta_tol: outer-iteration heading change (radians) below which the search stops.
        max_iterations: simplex iterations per outer iteration.
        max_outer: outer iterations (re-simulations).
        penalty: cost of an invalid candidate pose.
        seed: seed of the random initial simplex.
    """

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("spacing", "simplex_size"),
        ">= 0": ("straw_t", "orientation_step", "err_threshold", "xy_tol", "theta_tol", "penalty", "seed"),
        ">= 1": ("window", "n_orientations", "max_iterations", "max_outer"),
        "(0, 1]": ("line_threshold",)}

    spacing: float = 1.0
    window: int = 1
    straw_t: float = 0.99
    line_threshold: float = 0.95
    close_through_origin: bool = True
    n_orientations: int = 7
    orientation_step: float = math.radians(1.0)
    simplex_size: float = 1.0
    err_threshold: float = 0.01
    xy_tol: float = 0.005
    theta_tol: float = math.radians(0.05)
    max_iterations: int = 60
    max_outer: int = 8
    penalty: float = 1e3
    seed: int = 0


def scan_corners(ranges: np.ndarray, laser: LaserSpec, config: TfConfig = TfConfig()) -> np.ndarray:
    """ShortStraw corners of one scan, ``(K, 2)`` in the sensor frame (metres).

    No-return beams are dropped and their neighbours joined (see module notes).
    """
    pts = laser.to_points(ranges)
    return shortstraw(pts, config.spacing, config.window, config.straw_t, config.line_threshold)


def scan_polygon(corners: np.ndarray, config: TfConfig = TfConfig()) -> np.ndarray:
    """The closed scan polygon of a scan's corners (through the sensor origin if configured)."""
    if config.close_through_origin:
        return np.concatenate((_ORIGIN, corners))
    return corners


def scan_turning_function(ranges: np.ndarray, laser: LaserSpec,
                          config: TfConfig = TfConfig()) -> TurningFunction | None:
    """Turning function of a scan, or ``None`` if its polygon is degenerate (< 3 edges)."""
    try:
        return turning_function(scan_polygon(scan_corners(ranges, laser, config), config))
    except ValueError:
        return None


@dataclass
class _Cost:
    """Cost evaluations of one problem (Eq. 13 with the seven-orientation check), cached by position."""

    problem: Problem
    config: TfConfig
    real: TurningFunction
    evaluations: int = 0
    cache: dict = field(default_factory=dict)

    def errors(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Err and rotation offset (radians) at each of ``(N, 3)`` poses (one batched raycast)."""
        cfg, prob = self.config, self.problem
        errs = np.full(len(poses), cfg.penalty)
        rots = np.zeros(len(poses))
        xy = poses[:, :2]
        if len(poses) > 1 and (xy == xy[0]).all():  # the seven orientations share one position
            free = np.repeat(prob.map.is_free(xy[:1]), len(poses))
        else:
            free = prob.map.is_free(xy)
        if free.any():
            scans = prob.map.raycast(poses[free], prob.laser)
            for j, ranges in zip(np.flatnonzero(free), scans, strict=True):
                tf_v = scan_turning_function(ranges, prob.laser, cfg)
                if tf_v is not None:
                    m = match(self.real, tf_v)
                    errs[j], rots[j] = m.distance, m.rotation
        self.evaluations += len(poses)
        return errs, rots

    def function1(self, xy: np.ndarray, theta_v: float) -> tuple[float, float, float]:
        """Alg. 5's Function1: best Err over the orientations around ``theta_v`` at ``xy``.

        Returns (Err, heading of the best orientation, its rotation offset)."""
        key = (float(xy[0]), float(xy[1]))
        if key not in self.cache:
            k = np.arange(self.config.n_orientations) - (self.config.n_orientations - 1) / 2
            th = theta_v + k * self.config.orientation_step
            poses = np.column_stack((np.full_like(th, xy[0]), np.full_like(th, xy[1]), th))
            errs, rots = self.errors(poses)
            b = int(np.argmin(errs))
            self.cache[key] = (float(errs[b]), float(th[b]), float(rots[b]))
        return self.cache[key]


def simplex(cost: _Cost, start: Pose, size: float, rng: np.random.Generator) -> tuple[np.ndarray, int]:
    """Algorithm 5: Nelder–Mead over (x, y) with the heading fixed at ``start.theta``.

    Returns the best vertex (metres) and the number of iterations."""
    cfg, th = cost.config, start.theta
    phi = rng.uniform(0.0, 2.0 * math.pi)
    pts = [start.xy, start.xy + size * np.array([math.cos(phi), math.sin(phi)]),
           start.xy + size * np.array([math.cos(phi + math.pi / 3), math.sin(phi + math.pi / 3)])]
    f = lambda p: cost.function1(p, th)[0]  # noqa: E731
    it = 0
    while it < cfg.max_iterations:
        pts.sort(key=f)
        b, nb, w = pts
        if f(b) <= cfg.err_threshold or max(np.hypot(*(b - nb)), np.hypot(*(b - w))) < cfg.xy_tol:
            break
        it += 1
        cen = 0.5 * (b + nb)
        r = cen + (cen - w)
        if f(r) < f(b):
            e = r + (r - cen)
            w = r if f(r) < f(e) else e
        elif f(r) < f(nb):
            w = r
        else:
            c = 0.5 * (cen + r) if f(r) < f(w) else 0.5 * (cen + w)
            if f(c) < f(w):
                w = c
            else:  # shrink towards B: the step Alg. 5 lacks (see module notes)
                nb, w = 0.5 * (b + nb), 0.5 * (b + w)
        pts = [b, nb, w]
    return min(pts, key=f), it


class TurningFunctionMatcher(Configured):
    """The paper's method (``tf``): turning-function scan matching with a Nelder–Mead simplex."""

    name = "tf"
    CONFIG = TfConfig

    def localize(self, problem: Problem) -> Estimate:
        cfg = self.config
        real = scan_turning_function(problem.ranges, problem.laser, cfg)
        if real is None:
            return Estimate(problem.initial, False, 0, 0, {"status": "no-answer",
                                                           "reason": "real scan has < 3 polygon edges"})
        cost = _Cost(problem, cfg, real)
        rng = np.random.default_rng(cfg.seed)
        pose, size, iters, converged = problem.initial, cfg.simplex_size, 0, False
        err, outer = cost.function1(pose.xy, pose.theta)[0], 0
        while outer < cfg.max_outer:
            outer += 1
            xy, n = simplex(cost, pose, size, rng)
            iters += n
            err, heading, rot = cost.function1(xy, pose.theta)
            new = Pose(float(xy[0]), float(xy[1]), float(wrap_angle(heading - rot)))
            moved, turned = new.distance_to(pose), abs(wrap_angle(new.theta - pose.theta))
            pose, size = new, max(size / 2.0, 10 * cfg.xy_tol)
            cost.cache.clear()
            if err <= cfg.err_threshold or (moved < cfg.xy_tol and turned < cfg.theta_tol):
                converged = True
                break
        return Estimate(pose, converged, iters, cost.evaluations,
                        {"err": float(err), "outer": outer, "corners": int(real.n_edges)})

    def score(self, problem: Problem, pose: Pose) -> float:
        """Eq. 13's Err at exactly ``pose`` (no orientation search); ``penalty`` if degenerate."""
        real = scan_turning_function(problem.ranges, problem.laser, self.config)
        if real is None:
            return float(self.config.penalty)
        return float(_Cost(problem, self.config, real).errors(pose.as_array()[None, :])[0][0])
