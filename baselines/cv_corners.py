"""``cv-corners``: OpenCV ``estimateAffinePartial2D`` on ShortStraw corners of the real and virtual scans.

Inputs are the map, the laser spec, the real scan and the initial pose (never the truth). Choices
and why (the detail and the measurements: ``docs/baselines/cv-corners.md``):

* **Corners by** ``tf``'s **ShortStraw** (:func:`tfloc.paper.shape.scan_corners`) on the real scan
  and on the virtual scan at the current estimate, so that one detector sees the same occlusions in
  both, on any map; resampled every ``corner_spacing``, not ``tf``'s 1 m, because a corner lands
  on a resampled point.
* **Noise corners dropped** (:mod:`tfloc.baselines._corner_thin`): so finely resampled, the straws
  see the range noise; a corner whose raw neighbourhood is straight within ``straight_tol`` goes.
* **Sub-sample corners** (:mod:`tfloc.baselines._corner_refine`): a corner between two straight
  pieces moves to their fitted lines' intersection; else the noise makes the pose jitter.
* **Fair rigid hypotheses** (:mod:`tfloc.baselines._corner_match`): fed every candidate pair,
  ``estimateAffinePartial2D`` collapses the scale to 0; so corner pairs of agreeing length propose
  transforms within the protocol's window, scored by one-to-one inliers, drawn in a seeded order
  and stopped as adaptive RANSAC stops.
* **Refined by OpenCV** (RANSAC on the best hypothesis's inliers), projected onto SE(2), and
  **re-simulated** at the estimate until a step is small: the two viewpoints then coincide.
* A first step without an answer returns the initial pose with ``info["status"] = "no-answer"``;
  a later one keeps the last estimate.

``score(problem, pose)``: minus the one-to-one corner inliers between the real scan and the virtual
scan at ``pose``, plus their mean distance / ``inlier_tol`` (a tie-breaker in [0, 1]).
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
from tfloc.core.traits import Confidence
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

    corner_spacing: float = 0.02  #: ShortStraw's resampling distance S (metres)
    straight_tol: float = 0.03  #: drop a corner if its raw points lie this near a chord (metres; 0: off)
    refine_corners: bool = True  #: move corners to the fitted lines' intersection
    length_tol: float = 0.15  #: pairs' lengths agree within this (metres)
    min_pair_length: float = 0.5  #: shorter pairs give no rotation (metres)
    max_angle_deg: float = 25.0  #: a step's rotation window (degrees; csm-corr's 20° + margin)
    max_shift: float = 4.0  #: a step's shift window (metres; csm-corr's 3.5 m + margin)
    max_hypotheses: int = 5000  #: transforms scored per step, at most
    confidence: float = 0.999  #: adaptive stop: P(a supporting pair was drawn)
    seed: int = 0  #: seed of the corner pairs' draw order
    inlier_tol: float = 0.20  #: inlier distance; OpenCV's threshold, step 1 (metres)
    fine_tol: float = 0.03  #: OpenCV's threshold after step 1 (metres)
    ransac_max_iters: int = 2000  #: OpenCV's RANSAC iterations
    ransac_confidence: float = 0.99  #: OpenCV's RANSAC confidence
    max_scale_error: float = 0.05  #: reject OpenCV's answer if |scale − 1| > this
    max_iterations: int = 6  #: re-simulation steps, at most
    step_xy_tol: float = 0.005  #: converged: a step moves less than this (metres) ...
    step_theta_tol_deg: float = 0.05  #: ... and turns less than this (degrees)
    virtual_surface: str = "near-face"  #: on a grid: near-face (ray cast) or run-centre (mid-run)


class _NoAnswer(Exception):
    """A step could not produce a transform (too few corners, hypotheses or inliers; bad scale)."""


class CvCornersMatcher:
    """Corner matching with fair rigid hypotheses, refined by OpenCV (see the module docstring)."""

    name = "cv-corners"
    CONFIDENCE = Confidence("inliers", True, "the number of corner pairs its transform explains")

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
        """Match corners, refine with OpenCV, re-simulate at the estimate and repeat;
        ``info["hypotheses_total"]`` counts the transforms scored in all steps."""
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


REGISTRY = {"cv-corners": {"class": "CvCornersMatcher", "docs": "baselines/cv-corners.md", "summary": (
    "ShortStraw corners, fair rigid hypotheses, OpenCV `estimateAffinePartial2D` (RANSAC)")}}
