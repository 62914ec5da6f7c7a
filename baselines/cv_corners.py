"""``cv-corners``: OpenCV ``estimateAffinePartial2D`` on ShortStraw corners of the real and virtual scans.

Inputs are the map, the laser spec, the real scan and the initial pose (never the truth).
Configuration choices and why:

* **Corners by the same code path as** ``tf``: ``tfloc.paper.matcher.scan_corners`` (ShortStraw, Alg. 1–3)
  on the real scan and on the virtual scan ray-cast from the current pose estimate (at first the
  initial pose). The virtual scan, not the map's vertices, so that both corner sets come from the
  same detector and see the same occlusions; it works for any map (vector or grid). The one
  setting changed from ``tf``'s defaults is the resampling distance ``corner_spacing`` = 2 cm
  (``tf`` uses S = 1 m): corners land on resampled points, so S bounds their accuracy.
* **Sub-sample corner positions** (``refine_corners``, :mod:`tfloc.baselines._corner_refine`): a
  corner between two straight pieces of the scan moves to the intersection of the lines fitted
  to the raw points of those pieces; jump edges and field-of-view ends stay as ShortStraw put
  them. Without it, range noise (σ = 1 cm) leaves corners 1–3 cm off and the pose jitters by as
  much.
* **Fair correspondences**: ``estimateAffinePartial2D`` fed all candidate pairs collapses the
  scale to 0, so candidate rigid transforms are first proposed by every ordered pair of real
  corners and pair of virtual corners whose lengths agree within ``length_tol`` = 15 cm (pairs
  shorter than ``min_pair_length`` = 0.5 m give no usable rotation), restricted to the window the
  protocol's initial guess is known to lie in (``max_angle_deg`` = 25°, ``max_shift`` = 4 m per
  step, the same prior as ``csm-corr``'s ±3.5 m / ±20° plus a margin). Each is scored by its one-to-one
  (mutual nearest neighbour) inliers within ``inlier_tol`` = 20 cm, ties broken by the summed
  inlier distance. The truth is never used. Real scans can have 100+ corners (10⁴ ordered pairs
  a side); at most ``max_hypotheses`` = 5000 hypotheses, an evenly strided subset, are scored
  (the bundled office scans need at most ~6700, so 9 of 3240 are affected; a CSAIL relation
  took 40 s and tens of GB with no cap).
* **Refinement by OpenCV**: the best hypothesis's inlier pairs go to
  ``cv2.estimateAffinePartial2D`` with RANSAC (reprojection threshold ``inlier_tol`` on the first
  step, when the two viewpoints still differ, then ``fine_tol`` = 3 cm; OpenCV's default
  Levenberg–Marquardt refinement). A result with |scale − 1| > ``max_scale_error`` = 0.05 is
  rejected; otherwise it is projected onto SE(2) (scale dropped).
* **Re-simulation**: the virtual scan is ray-cast again at the new estimate and the match repeated
  (up to ``max_iterations`` = 6; ``converged`` when a step moves < 5 mm and < 0.05°). As the two
  viewpoints coincide, both corner sets see the same occlusions and field-of-view ends.
* Choices measured on the quick test-room check (``benchmarks/baselines_quick.py``, 90 problems,
  0–3 m / 0–15°): with the hypothesis window restricted to ±3° / 0.3 m after the first step
  success was 70 %, with the full window at every step 78 % (so the full window is kept);
  ``corner_spacing`` 2 cm vs 5 cm: 78 % vs 80 % and median 17 vs 12 ms per scan, 2 cm kept
  because its estimates settle (converge) where 5 cm ones keep jittering by a few mm;
  without corner refinement (2 cm): 71 %.
* Fewer than 2 corners in either scan, no hypothesis, fewer than 2 inliers or a rejected scale on
  the first step is a ``no-answer``: the initial pose is returned with ``converged=False`` and
  ``info["status"] = "no-answer"`` (never an exception). A later step that fails keeps the last
  good estimate.

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
from tfloc.paper.matcher import TfConfig, scan_corners

from ._corner_match import best_hypothesis, mutual_inliers, pair_hypotheses
from ._corner_refine import refine_corners


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`CvCornersMatcher` (metres, degrees where named)."""

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("corner_spacing", "inlier_tol", "fine_tol"),
        ">= 0": ("length_tol", "min_pair_length", "max_angle_deg", "max_shift", "max_scale_error",
                 "step_xy_tol", "step_theta_tol_deg"),
        ">= 1": ("max_hypotheses", "ransac_max_iters", "max_iterations"),
        "(0, 1)": ("ransac_confidence",)}

    corner_spacing: float = 0.02
    refine_corners: bool = True
    length_tol: float = 0.15
    min_pair_length: float = 0.5
    max_angle_deg: float = 25.0
    max_shift: float = 4.0
    max_hypotheses: int = 5000
    inlier_tol: float = 0.20
    fine_tol: float = 0.03
    ransac_max_iters: int = 2000
    ransac_confidence: float = 0.99
    max_scale_error: float = 0.05
    max_iterations: int = 6
    step_xy_tol: float = 0.005
    step_theta_tol_deg: float = 0.05


class _NoAnswer(Exception):
    """A step could not produce a transform (too few corners, hypotheses or inliers; bad scale)."""


class CvCornersMatcher:
    """Corner matching with fair rigid hypotheses, refined by OpenCV (see the module docstring)."""

    name = "cv-corners"

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        self.config = resolve_params(Config, config, overrides)
        self._tf_config = TfConfig(spacing=self.config.corner_spacing)

    def _corners(self, ranges: np.ndarray, problem: Problem) -> np.ndarray:
        if int(problem.laser.valid(ranges).sum()) < 2:
            return np.empty((0, 2))
        with np.errstate(invalid="ignore"):  # LaserSpec.to_points computes inf·cos(±90°) before masking
            corners = np.asarray(scan_corners(ranges, problem.laser, self._tf_config), dtype=float).reshape(-1, 2)
            if self.config.refine_corners:
                corners = refine_corners(corners, problem.laser.to_points(ranges))
        return corners

    def _step(self, real: np.ndarray, problem: Problem, pose: Pose, first: bool) -> tuple[Pose, dict]:
        """One match of the real corners against the virtual scan's corners at ``pose``."""
        c = self.config
        virtual = self._corners(problem.map.raycast(pose, problem.laser), problem)
        if len(real) < 2 or len(virtual) < 2:
            raise _NoAnswer(f"too few corners (real {len(real)}, virtual {len(virtual)})")
        # The window bounds the correction of this step, relative to ``pose``.
        hyp = pair_hypotheses(real, virtual, c.length_tol, c.min_pair_length,
                              math.radians(c.max_angle_deg), c.max_shift, c.max_hypotheses)
        if hyp.theta.size == 0:
            raise _NoAnswer("no corner pairs of agreeing length")
        _, partner, _ = best_hypothesis(real, virtual, hyp, c.inlier_tol)
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
                     "hypotheses": int(hyp.theta.size), "inliers": int(mask.sum()), "scale": float(scale)}

    def localize(self, problem: Problem) -> Estimate:
        """Match corners, refine with OpenCV, re-simulate at the estimate and repeat."""
        c = self.config
        real = self._corners(problem.ranges, problem)
        pose, info, steps = problem.initial, {}, 0
        converged = False
        for steps in range(1, c.max_iterations + 1):
            try:
                new, info = self._step(real, problem, pose, first=steps == 1)
            except _NoAnswer as exc:
                if steps == 1:
                    return Estimate(problem.initial, False, iterations=1,
                                    info={"status": "no-answer", "reason": str(exc)})
                info = {**info, "last_step": f"failed: {exc}"}
                break
            small = (new.distance_to(pose) < c.step_xy_tol
                     and abs(angdiff(new.theta, pose.theta)) < math.radians(c.step_theta_tol_deg))
            pose = Pose(new.x, new.y, float(wrap_angle(new.theta)))
            if small:
                converged = True
                break
        return Estimate(pose, converged, iterations=steps, info={"status": "ok", **info})

    def score(self, problem: Problem, pose: Pose) -> float:
        """−(one-to-one corner inliers at ``pose``) + mean inlier distance / inlier_tol; lower is better."""
        real = self._corners(problem.ranges, problem)
        virtual = self._corners(problem.map.raycast(pose, problem.laser), problem)
        if len(real) == 0 or len(virtual) == 0:
            return 0.0
        partner, dist = mutual_inliers(np.zeros(1), np.zeros((1, 2)), real, virtual, self.config.inlier_tol)
        inl = partner[0] >= 0
        n = int(inl.sum())
        return float(-n + (dist[0, inl].mean() / self.config.inlier_tol if n else 0.0))
