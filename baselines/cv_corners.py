"""``cv-corners``: OpenCV ``estimateAffinePartial2D`` on ShortStraw corners of the real and virtual scans.

Inputs are the map, the laser spec, the real scan and the initial pose (never the truth).
Configuration choices and why:

* **Corners by the same code path as** ``tf``: ``tfloc.paper.shape.scan_corners`` (ShortStraw, Alg. 1–3)
  on the real scan and on the virtual scan ray-cast from the current pose estimate (at first the
  initial pose). The virtual scan, not the map's vertices, so that both corner sets come from the
  same detector and see the same occlusions; it works for any map (vector or grid). The one
  setting changed from ``tf``'s defaults is the resampling distance ``corner_spacing`` = 2 cm
  (``tf`` uses S = 1 m): corners land on resampled points, so S bounds their accuracy.
* **Noise corners dropped** (``straight_tol`` = 3 cm, :mod:`tfloc.baselines._corner_thin`): at S = 2 cm
  the straws see the range noise, and a wall scanned from close by (raw points 1–2 cm apart) gets
  a corner every few centimetres: 19.5 corners per simulated office scan where the noise-free
  virtual scan at the truth has 13.5, and 75 (max 117) per real MIT CSAIL relation scan where
  its virtual scan has 38. A corner is dropped when every raw point from the last kept corner to
  the next lies within ``straight_tol`` of the chord between them (Alg. 3's "is it a line?"
  asked of the raw points with a noise-sized tolerance; one pass as Alg. 3). 3 cm = 3σ of the
  simulated noise; it brings the office scans to 15 corners (virtual 13.5) and the CSAIL
  relation scans to 50. ``straight_tol`` = 0 switches it off.
* **Sub-sample corner positions** (``refine_corners``, :mod:`tfloc.baselines._corner_refine`): a
  corner between two straight pieces of the scan moves to the intersection of the lines fitted
  to the raw points of those pieces; jump edges and field-of-view ends stay as ShortStraw put
  them. Without it, range noise (σ = 1 cm) leaves corners 1–3 cm off and the pose jitters by as
  much.
* **Fair correspondences**: ``estimateAffinePartial2D`` fed all candidate pairs collapses the
  scale to 0, so candidate rigid transforms are first proposed by pairs of real corners and
  ordered pairs of virtual corners whose lengths agree within ``length_tol`` = 15 cm (pairs
  shorter than ``min_pair_length`` = 0.5 m give no usable rotation), restricted to the window the
  protocol's initial guess is known to lie in (``max_angle_deg`` = 25°, ``max_shift`` = 4 m per
  step, the same prior as ``csm-corr``'s ±3.5 m / ±20° plus a margin). Each is scored by its
  one-to-one (mutual nearest neighbour) inliers within ``inlier_tol`` = 20 cm, ties broken by
  the summed inlier distance. The truth is never used. Each real pair is taken once: the
  reversed pair onto the reversed virtual pair is the same transform.
* **Adaptive search** (``confidence`` = 0.999, ``seed`` = 0, :func:`tfloc.baselines._corner_match.search_hypotheses`):
  real corner pairs are drawn in a seeded random order, each matched with every virtual pair of
  agreeing length and each transform scored at once; the search stops as adaptive RANSAC does,
  once a pair supporting the best match so far would have been drawn with probability
  ``confidence`` (w = that match's supporting pairs / all real pairs, n ≥ log(1 − c)/log(1 − w)),
  and in any case after ``max_hypotheses`` = 5000 scored transforms per step (at most 6 × 5000
  per scan). ``confidence`` = 1 scores every hypothesis (up to the cap).
* **Refinement by OpenCV**: the best hypothesis's inlier pairs go to
  ``cv2.estimateAffinePartial2D`` with RANSAC (reprojection threshold ``inlier_tol`` on the first
  step, when the two viewpoints still differ, then ``fine_tol`` = 3 cm; OpenCV's default
  Levenberg–Marquardt refinement). A result with |scale − 1| > ``max_scale_error`` = 0.05 is
  rejected; otherwise it is projected onto SE(2) (scale dropped).
* **Re-simulation**: the virtual scan is ray-cast again at the new estimate and the match repeated
  (up to ``max_iterations`` = 6; ``converged`` when a step moves < 5 mm and < 0.05°). As the two
  viewpoints coincide, both corner sets see the same occlusions and field-of-view ends.
* ``straight_tol`` = 3 cm and ``confidence`` = 0.999 were chosen on a development subset and checked
  on held-out scans: the measurements are in ``docs/baselines/cv-corners.md``.
* Fewer than 2 corners in either scan, no hypothesis, fewer than 2 inliers or a rejected scale on
  the first step is a ``no-answer``: the initial pose is returned with ``converged=False`` and
  ``info["status"] = "no-answer"`` (never an exception). A later step that fails keeps the last
  good estimate. ``info["hypotheses_total"]`` counts the transforms scored in all steps.
* ``virtual_surface`` = ``near-face`` (the ray-cast range). ``run-centre`` ends each beam of the
  virtual scan in the middle of the occupied run it enters on a grid (as karto's base scans, see
  docs/baselines/karto.md); measured in issue 25 (docs/robustness.md): the same success on the
  as-built grids, more on hits-only and thickened maps, at 40–70 % more CPU; not the default.

``score(problem, pose)`` is its own objective at ``pose``: minus the number of one-to-one corner
inliers between the real scan and the virtual scan at ``pose`` (identity transform), plus their
mean distance divided by ``inlier_tol`` (a tie-breaker in [0, 1]).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import cv2
import numpy as np

from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose, angdiff, wrap_angle
from tfloc.core.problem import Estimate, Problem
from tfloc.paper.shape import ShapeConfig, scan_corners

from ._corner_match import mutual_inliers, search_hypotheses
from ._corner_refine import refine_corners
from ._corner_thin import drop_straight_corners
from ._scan_lattice import run_centre_ranges


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`CvCornersMatcher` (metres, degrees where named)."""

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("corner_spacing", "inlier_tol", "fine_tol"),
        ">= 0": ("straight_tol", "length_tol", "min_pair_length", "max_angle_deg", "max_shift",
                 "max_scale_error", "step_xy_tol", "step_theta_tol_deg", "seed"),
        ">= 1": ("max_hypotheses", "ransac_max_iters", "max_iterations"),
        "(0, 1)": ("confidence", "ransac_confidence",),
        ("near-face", "run-centre"): ("virtual_surface",)}

    corner_spacing: float = 0.02
    straight_tol: float = 0.03
    refine_corners: bool = True
    length_tol: float = 0.15
    min_pair_length: float = 0.5
    max_angle_deg: float = 25.0
    max_shift: float = 4.0
    max_hypotheses: int = 5000
    confidence: float = 0.999
    seed: int = 0
    inlier_tol: float = 0.20
    fine_tol: float = 0.03
    ransac_max_iters: int = 2000
    ransac_confidence: float = 0.99
    max_scale_error: float = 0.05
    max_iterations: int = 6
    step_xy_tol: float = 0.005
    step_theta_tol_deg: float = 0.05
    virtual_surface: str = "near-face"


class _NoAnswer(Exception):
    """A step could not produce a transform (too few corners, hypotheses or inliers; bad scale)."""


class CvCornersMatcher:
    """Corner matching with fair rigid hypotheses, refined by OpenCV (see the module docstring)."""

    name = "cv-corners"

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        self.config = resolve_params(Config, config, overrides)
        self._shape = ShapeConfig(spacing=self.config.corner_spacing)

    def _virtual(self, pose: Pose, problem: Problem) -> np.ndarray:
        """The virtual scan at ``pose``: the ray-cast range, or on a grid with ``virtual_surface``
        = ``run-centre`` the middle of the occupied run each beam enters (see _scan_lattice)."""
        r = problem.map.raycast(pose, problem.laser)
        if self.config.virtual_surface == "run-centre" and hasattr(problem.map, "occupied"):
            r = run_centre_ranges(problem.map, pose.as_array()[None, :], problem.laser, r[None, :])[0]
        return r

    def _corners(self, ranges: np.ndarray, problem: Problem) -> np.ndarray:
        if int(problem.laser.valid(ranges).sum()) < 2:
            return np.empty((0, 2))
        with np.errstate(invalid="ignore"):  # LaserSpec.to_points computes inf·cos(±90°) before masking
            corners = np.asarray(scan_corners(ranges, problem.laser, self._shape), dtype=float).reshape(-1, 2)
            points = problem.laser.to_points(ranges)
            if self.config.straight_tol > 0:
                corners = drop_straight_corners(corners, points, self.config.straight_tol)
            if self.config.refine_corners:
                corners = refine_corners(corners, points)
        return corners

    def _step(self, real: np.ndarray, problem: Problem, pose: Pose, first: bool,
              scored: list[int]) -> tuple[Pose, dict]:
        """One match of the real corners against the virtual scan's corners at ``pose``; appends
        the number of hypotheses it scored to ``scored``."""
        c = self.config
        virtual = self._corners(self._virtual(pose, problem), problem)
        if len(real) < 2 or len(virtual) < 2:
            raise _NoAnswer(f"too few corners (real {len(real)}, virtual {len(virtual)})")
        # The window bounds the correction of this step, relative to ``pose``.
        found = search_hypotheses(real, virtual, c.length_tol, c.min_pair_length, math.radians(c.max_angle_deg),
                                  c.max_shift, c.inlier_tol, c.confidence, c.max_hypotheses, c.seed)
        scored.append(0 if found is None else found.scored)
        if found is None:
            raise _NoAnswer("no corner pairs of agreeing length")
        partner = mutual_inliers(np.array([found.theta]), found.t[None], real, virtual, c.inlier_tol)[0][0]
        src = real[partner >= 0]
        dst = virtual[partner[partner >= 0]]
        if len(src) < 2:
            raise _NoAnswer(f"{len(src)} corner inlier(s)")
        m, mask = cv2.estimateAffinePartial2D(
            src.astype(np.float32).reshape(-1, 1, 2), dst.astype(np.float32).reshape(-1, 1, 2),
            method=cv2.RANSAC, ransacReprojThreshold=c.inlier_tol if first else c.fine_tol,
            maxIters=c.ransac_max_iters, confidence=c.ransac_confidence)
        if m is None:
            raise _NoAnswer("estimateAffinePartial2D found no transform")
        scale = math.hypot(m[0, 0], m[1, 0])
        if abs(scale - 1.0) > c.max_scale_error:
            raise _NoAnswer(f"scale {scale:.3f} rejected")
        theta = math.atan2(m[1, 0], m[0, 0])
        # Real sensor frame → virtual sensor frame (at ``pose``): the robot is at pose ⊕ that.
        new = pose.compose(Pose(float(m[0, 2]), float(m[1, 2]), theta))
        return new, {"corners_real": int(len(real)), "corners_virtual": int(len(virtual)),
                     "hypotheses": found.scored, "pairs_drawn": found.drawn, "pairs": found.pairs,
                     "inliers": int(mask.sum()), "scale": float(scale)}

    def localize(self, problem: Problem) -> Estimate:
        """Match corners, refine with OpenCV, re-simulate at the estimate and repeat."""
        c = self.config
        real = self._corners(problem.ranges, problem)
        pose, info, steps = problem.initial, {}, 0
        converged = False
        scored: list[int] = []
        for steps in range(1, c.max_iterations + 1):
            try:
                new, info = self._step(real, problem, pose, steps == 1, scored)
            except _NoAnswer as exc:
                if steps == 1:
                    return Estimate(problem.initial, False, iterations=1,
                                    info={"status": "no-answer", "reason": str(exc),
                                          "hypotheses_total": sum(scored)})
                info = {**info, "last_step": f"failed: {exc}"}
                break
            small = (new.distance_to(pose) < c.step_xy_tol
                     and abs(angdiff(new.theta, pose.theta)) < math.radians(c.step_theta_tol_deg))
            pose = Pose(new.x, new.y, float(wrap_angle(new.theta)))
            if small:
                converged = True
                break
        return Estimate(pose, converged, iterations=steps,
                        info={"status": "ok", **info, "hypotheses_total": sum(scored)})

    def score(self, problem: Problem, pose: Pose) -> float:
        """−(one-to-one corner inliers at ``pose``) + mean inlier distance / inlier_tol; lower is better."""
        real = self._corners(problem.ranges, problem)
        virtual = self._corners(self._virtual(pose, problem), problem)
        if len(real) == 0 or len(virtual) == 0:
            return 0.0
        partner, dist = mutual_inliers(np.zeros(1), np.zeros((1, 2)), real, virtual, self.config.inlier_tol)
        inl = partner[0] >= 0
        n = int(inl.sum())
        return float(-n + (dist[0, inl].mean() / self.config.inlier_tol if n else 0.0))
