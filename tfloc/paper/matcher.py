"""The paper's pose search: turning-function matching driven by a Nelder–Mead simplex.

Sec. 4.4, Eq. 13 and Algorithm 5. A *cost evaluation* matches the turning function (ShortStraw
corners, Algs. 1–4) of the virtual scan (VSD) at a candidate pose against the real scan's (Sec.
4.3); Alg. 5's ``Function1(P, θ_v)`` keeps the best of seven orientations around θ_v at P.

Readings (the text is ambiguous or wrong; each choice is the one that works):

* **Scan polygon.** Alg. 4 needs a closed counter-clockwise polygon; a 180° scan is an open
  polyline. We close it through the sensor origin (counter-clockwise and simple by
  construction); closing it directly can self-intersect (``close_through_origin=False``).
* **No-return beams** are dropped and their neighbours joined (one short chord per dropout;
  clipping to max range would add a spurious arc).
* **Alg. 5's W** is "the point with 2nd maximum error", i.e. NB of three: read as the worst.
* **Alg. 5 has no shrink step**: it accepts a contraction no better than W, so W creeps onto the
  midpoint of B and NB and the simplex never converges (observed: 60 iterations on one repeated
  point). We add Nelder–Mead's shrink towards B for that case only, and stop when the simplex
  is smaller than ``xy_tol`` or after ``max_iterations`` (Alg. 5 has no convergence test).
* **Function1(P, θ_v)** depends on P only (θ_v is fixed while the simplex runs): cached. Its
  seven orientations are θ_v + k·``orientation_step``, k = −3…3 (the paper gives no step).
* **Outer iterations** (Eq. 2, Δθ = Σδθ_k): the pose becomes the best vertex, its heading the
  best of the seven corrected by the histogram's rotation offset (Sec. 4.3); the simplex restarts
  there, halved, until Err ≤ ``err_threshold`` or the pose moves less than the tolerances.
* **Initial simplex** ("three random points … covering the maximum position difference"): the VP
  and two points ``simplex_size`` metres away at a seeded random direction, 60° apart.
* **Invalid candidates** (in a wall, off the map, < 2 corners) cost ``penalty``.

Ambiguous readings are switches of :class:`TfConfig` (each quoting the sentence it reads);
``tf-best`` (:mod:`tfloc.paper.best`) takes the best-measured reading of each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from tfloc.core.params import Configured
from tfloc.core.pose import Pose, wrap_angle
from tfloc.core.problem import Estimate, Problem
from tfloc.errors import ParameterError
from tfloc.maps.inside import SURE
from tfloc.maps.vector import VectorMap

from .kernels import function1_kernel, scan_errors
from .search_kernel import search_kernel
from .shape import ShapeConfig, scan_turning_function
from .turning import TurningFunction

_NORMS = ("l2", "l1")


@dataclass(frozen=True)
class TfConfig:
    """Parameters of the ``tf`` matcher; defaults follow the paper where it gives a value and are
    otherwise the literal reading of ``main`` (the switches below name the alternatives).

    Attributes:
        spacing, window, straw_t, line_threshold, resampling, close_through_origin: how a scan
            becomes a polygon (Algs. 1–4), :class:`tfloc.paper.shape.ShapeConfig` (the readings
            of the text, quoted there; a line each below); :attr:`shape` collects them.
        err_norm: Err. ``"l2"`` (default): Eq. 13, "Err = (∫₀¹ |Θ_R(L) − Θ_V(L)|² dL)^½";
            ``"l1"``: Sec. 4.3, "The area between the two graphs is then computed. Rectangles are
            created between two graphs because they are in the form of histograms. Each
            rectangle's area is determined, and the area between the two graphs is calculated by
            adding the total areas together." (∫|Θ_R − Θ_V − θ|, best θ = weighted median).
        n_orientations: orientations checked per simplex vertex (7: "the angle of each of these
            three vertices is examined locally in seven orientations").
        orientation_step: spacing of those orientations (radians). The paper gives none; the
            literal default is 1°, the scanner's "angular resolution of 1 degree" (the seven
            cover ±3°). 5° makes them cover ±15°, the protocol's largest angle offset ("The
            angle difference in this scenario ranges from 0 to 15 degrees").
        rotation_correction: after a simplex run, correct the heading by the histogram's rotation
            offset (Sec. 4.3's transfer "to the same coordinate system"; default ``True``) or
            keep the best of the seven orientations only (``False``).
        heading_clamp: the largest heading change (radians) from the initial heading the outer
            iterations may make. Default ``inf`` (unbounded, as written: Eq. 2's Δθ = Σ δθ_k has
            no bound). A finite value reads "the angle of each of these three vertices is
            examined locally" as a bound; the protocol's largest initial angle offset is 15°.
        simplex_size: initial simplex size (metres). "Three points are chosen at random in an
            arbitrary interval in the beginning. The maximum value of the robot position
            difference should be covered by this interval." Literal default: a fixed 1 m; the
            covering reading is the protocol's largest offset, 3 m ("The difference in the
            position ... ranges from 0 to 300 cm").
        keep_best: across outer iterations, return the pose of lowest Err (``True``) or the last
            pose (``False``, default). Alg. 5 keeps the best within one run ("B ← find the point
            among B, NB and W with minimum error"); of the repetition the text says only "This
            operation is iterated by the algorithm until a suitable fixation between the two
            positions is found", which leaves the answer of the last iteration.
    """

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("spacing", "simplex_size", "heading_clamp"),
        ">= 0": ("straw_t", "orientation_step", "err_threshold", "xy_tol", "theta_tol", "penalty", "seed"),
        ">= 1": ("window", "n_orientations", "max_iterations", "max_outer"),
        "(0, 1]": ("line_threshold",)}

    spacing: float = 1.0  #: S of Alg. 1, the resampling distance (metres)
    window: int = 1  #: w of Alg. 2 (points)
    straw_t: float = 0.99  #: t of Alg. 2
    line_threshold: float = 0.95  #: Is-Line threshold of Alg. 3
    close_through_origin: bool = True  #: close the polygon through the sensor (Alg. 4)
    n_orientations: int = 7
    orientation_step: float = math.radians(1.0)
    simplex_size: float = 1.0
    err_threshold: float = 0.01  #: Eq. 13's threshold on Err (rad; rad × unit length for l1)
    xy_tol: float = 0.005  #: stop below this simplex size and outer move (metres)
    theta_tol: float = math.radians(0.05)  #: ... and this outer heading change (radians)
    max_iterations: int = 60  #: simplex iterations per outer iteration
    max_outer: int = 8  #: outer iterations (re-simulations)
    penalty: float = 1e3  #: cost of an invalid candidate pose
    seed: int = 0  #: seed of the random initial simplex
    err_norm: str = "l2"
    resampling: str = "chord"  #: how Alg. 1 steps: "chord" or "path"
    rotation_correction: bool = True
    heading_clamp: float = math.inf
    keep_best: bool = False

    @property
    def shape(self) -> ShapeConfig:
        """The parameters of the scan's shape (Algs. 1–4)."""
        return ShapeConfig(self.spacing, self.window, self.straw_t, self.line_threshold,
                           self.resampling, self.close_through_origin)

    def __post_init__(self) -> None:
        if self.err_norm not in _NORMS:
            raise ParameterError(f"tf: err_norm must be one of {_NORMS}, not {self.err_norm!r}", ("err_norm",))
        self.shape  # noqa: B018 - validates the shape parameters
        if not self.heading_clamp > 0:
            raise ParameterError(f"tf: heading_clamp must be > 0 radians (inf = unbounded), not {self.heading_clamp!r}",
                                 ("heading_clamp",))


@dataclass
class _Cost:
    """Cost evaluations of one problem (Eq. 13 with the seven-orientation check), cached by position."""

    problem: Problem
    config: TfConfig
    real: TurningFunction
    evaluations: int = 0
    cache: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        cfg, laser = self.config, self.problem.laser
        n = cfg.n_orientations
        self._offsets = (np.arange(n) - (n - 1) / 2) * cfg.orientation_step
        self._kernel_args = (  # everything scan_errors needs after the scans, converted once
            laser.directions, float(laser.max_range), float(cfg.spacing), int(cfg.window),
            float(cfg.straw_t), float(cfg.line_threshold), bool(cfg.close_through_origin),
            cfg.resampling == "path", cfg.err_norm == "l1", self.real.breaks, self.real.angles,
            float(cfg.penalty))
        self._vector = None
        m = self.problem.map
        if isinstance(m, VectorMap):              # Function1 in one compiled call
            r = m.free_rings(build=True)            # hundreds of free tests per scan
            if r is not None:                       # (else shapely's geometry: the Python path)
                self._vector = (self._offsets, r.kernel, SURE,
                                np.asarray(laser.angles, dtype=float), m.segments,
                                m.segment_index(float(laser.max_range)))

    def _function1_vector(self, x: float, y: float, theta_v: float) -> tuple[float, float, float]:
        """:meth:`function1`'s evaluation on a vector map: one compiled call
        (:func:`tfloc.paper.kernels.function1_kernel`), shapely only near the free space's
        boundary; the same values as the general path."""
        offsets, rings, sure, angles, segs, index = self._vector
        code, err, heading, rot = function1_kernel(x, y, theta_v, offsets, rings, sure, angles,
                                                   segs, index, *self._kernel_args)
        if code < 0:
            if not self.problem.map.is_free(np.array([[x, y]]))[0]:
                return float(self.config.penalty), float(theta_v + offsets[0]), 0.0
            code, err, heading, rot = function1_kernel(x, y, theta_v, offsets, rings, -1.0, angles,
                                                       segs, index, *self._kernel_args)
        return float(err), float(heading), float(rot)

    def _scan_errors(self, scans: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Err and rotation offset (radians, in [-π, π)) of each virtual scan ``(P, n_beams)``:
        corners, turning functions and matching of all of them in one compiled call
        (:func:`tfloc.paper.kernels.scan_errors`)."""
        return scan_errors(scans, *self._kernel_args)

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
            errs[free], rots[free] = self._scan_errors(prob.map.raycast(poses[free], prob.laser))
        self.evaluations += len(poses)
        return errs, rots

    def function1(self, xy: np.ndarray, theta_v: float) -> tuple[float, float, float]:
        """Alg. 5's Function1: best Err over the orientations around ``theta_v`` at ``xy``.

        Returns (Err, heading of the best orientation, its rotation offset)."""
        key = (float(xy[0]), float(xy[1]))
        hit = self.cache.get(key)
        if hit is None and self._vector is not None:
            hit = self._function1_vector(key[0], key[1], theta_v)
            self.evaluations += len(self._offsets)
            self.cache[key] = hit
        if hit is None:
            th = theta_v + self._offsets
            poses = np.empty((len(th), 3))
            poses[:, 0], poses[:, 1], poses[:, 2] = key[0], key[1], th
            prob = self.problem
            # errors(poses) gives the same answer; inlined because its general masking costs
            # about a seventh of tf's time on this hot path
            if prob.map.is_free(poses[:1, :2])[0]:  # the orientations share one position
                errs, rots = self._scan_errors(prob.map.raycast(poses, prob.laser))
                b = int(np.argmin(errs))
                hit = (float(errs[b]), float(th[b]), float(rots[b]))
            else:
                hit = (float(self.config.penalty), float(th[0]), 0.0)
            self.evaluations += len(th)
            self.cache[key] = hit
        return hit


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

    def heading(self, best: float, rot: float, initial: float) -> float:
        """The heading after an outer iteration (radians): the best of the seven orientations,
        corrected by the rotation offset ``rot`` (if ``rotation_correction``), kept within
        ``heading_clamp`` of the ``initial`` heading."""
        cfg = self.config
        theta = float(wrap_angle(best - rot)) if cfg.rotation_correction else best
        if math.isfinite(cfg.heading_clamp):
            change = min(max(float(wrap_angle(theta - initial)), -cfg.heading_clamp), cfg.heading_clamp)
            theta = float(wrap_angle(initial + change))
        return theta

    def localize(self, problem: Problem) -> Estimate:
        cfg = self.config
        real = scan_turning_function(problem.ranges, problem.laser, cfg.shape)
        if real is None:
            return Estimate(problem.initial, False, 0, 0, {"status": "no-answer",
                                                           "reason": "real scan has < 3 polygon edges"})
        cost = _Cost(problem, cfg, real)
        if cost._vector is not None:
            est = self._search_compiled(problem, cost)
            if est is not None:
                return est
        rng = np.random.default_rng(cfg.seed)
        pose, size, iters, converged = problem.initial, cfg.simplex_size, 0, False
        err, outer = cost.function1(pose.xy, pose.theta)[0], 0
        best: tuple[float, Pose] | None = None
        while outer < cfg.max_outer:
            outer += 1
            xy, n = simplex(cost, pose, size, rng)
            iters += n
            err, heading, rot = cost.function1(xy, pose.theta)
            new = Pose(float(xy[0]), float(xy[1]), self.heading(heading, rot, problem.initial.theta))
            if best is None or err < best[0]:
                best = (err, new)
            moved, turned = new.distance_to(pose), abs(wrap_angle(new.theta - pose.theta))
            pose, size = new, max(size / 2.0, 10 * cfg.xy_tol)
            cost.cache.clear()
            if err <= cfg.err_threshold or (moved < cfg.xy_tol and turned < cfg.theta_tol):
                converged = True
                break
        if cfg.keep_best and best is not None:
            err, pose = best
        return Estimate(pose, converged, iters, cost.evaluations,
                        {"err": float(err), "outer": outer, "corners": int(real.n_edges)})

    def _search_compiled(self, problem: Problem, cost: _Cost) -> Estimate | None:
        """The search below in one compiled call on a vector map
        (:func:`tfloc.paper.search_kernel.search_kernel`: the same steps and values); ``None``
        where it gave up (then the Python search runs)."""
        cfg = self.config
        phis = np.random.default_rng(cfg.seed).uniform(0.0, 2.0 * math.pi, cfg.max_outer)
        ok, x, y, th, converged, iters, misses, err, outer = search_kernel(
            problem.initial.x, problem.initial.y, problem.initial.theta, phis,
            float(cfg.simplex_size), float(cfg.xy_tol), float(cfg.theta_tol),
            float(cfg.err_threshold), int(cfg.max_iterations), int(cfg.max_outer),
            bool(cfg.rotation_correction), float(cfg.heading_clamp), bool(cfg.keep_best),
            (*cost._vector, *cost._kernel_args))
        if not ok:
            return None
        return Estimate(Pose(float(x), float(y), float(th)), bool(converged), int(iters),
                        int(misses) * cfg.n_orientations,
                        {"err": float(err), "outer": int(outer), "corners": int(cost.real.n_edges)})

    def score(self, problem: Problem, pose: Pose) -> float:
        """Eq. 13's Err at exactly ``pose`` (no orientation search); ``penalty`` if degenerate."""
        real = scan_turning_function(problem.ranges, problem.laser, self.config.shape)
        if real is None:
            return float(self.config.penalty)
        return float(_Cost(problem, self.config, real).errors(pose.as_array()[None, :])[0][0])


REGISTRY = {"tf": {"class": "TurningFunctionMatcher", "docs": "single-scan.md", "files": ["tfloc/paper/corners.py", "tfloc/paper/turning.py"], "summary": (
    "the paper's method, as written; where the text is wrong or ambiguous the reading that "
    "works is chosen and documented (Alg. 1's squared distance, Alg. 3's squared path, Alg. "
    "5's missing shrink step, W = worst, the seven orientations, the scan polygon closed "
    "through the sensor, no-return beams)")}}
