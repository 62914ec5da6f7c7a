"""``tf-plus-track``: ``tf-plus`` run along a sequence that weighs the odometry's prediction when
the scan cannot tell two places apart.

Single-scan ``tf-plus`` searches ±``search_radius`` around its guess and takes the pose whose
scan residual is lowest. Along a recording that is the right answer to a one-scan question and
the wrong one for a robot: in a place whose geometry repeats (a corridor, a bare corner, people
in front of the laser) a pose metres away can explain the scan as well as the right one, and
the tracker jumps there. Two rules, each of them the robot's prior knowledge of its own motion:

1. **A jump must be earned.** When the answer lies beyond ``jump_gate_m`` / ``jump_gate_rad`` of
   the prediction, ``tf-plus`` is asked again without its position grid (its headings and the
   refinement from the prediction: the best pose *near* it), and the far answer is kept only if
   it explains the scan ``jump_ratio`` times better (the selection objective, RMS residual in
   metres); otherwise the near one is taken.
2. **An odometry increment the robot cannot have made is doubted.** An increment beyond
   ``max_step_m`` / ``max_step_rad`` per scan (a wheel encoder that froze and then caught up in
   one message) is also tried as no motion at all, from the last estimate; the better scoring
   answer wins.

A prediction ``tf-plus`` cannot answer (too few returns) is kept, as for every single-scan
matcher run as a tracker (:class:`~tfloc.core.tracker.LocalTracker`). The true pose is never
read. Its rules' values were chosen on the MIT CSAIL native sequence only (``docs/tracking.md``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose, wrap_angle
from tfloc.core.problem import Estimate, Problem
from tfloc.core.tracker import PREDICTED, LocalTracker

from .config import TfPlusConfig
from .matcher import TurningFunctionPlusMatcher


@dataclass(frozen=True)
class TfPlusTrackConfig:
    """Parameters of ``tf-plus-track`` (metres, radians; ``local``: ``tf-plus``'s own)."""

    RULES: ClassVar[dict] = {"> 0": ("jump_gate_m", "jump_gate_rad", "max_step_m", "max_step_rad"),
                             ">= 1": ("jump_ratio",)}

    jump_gate_m: float = 0.5  #: an answer farther than this from the prediction is a jump (metres) ...
    jump_gate_rad: float = math.radians(20.0)  #: ... or turned more than this (radians)
    jump_ratio: float = 1.5  #: a jump is kept only if the near answer's residual is this many times its own
    max_step_m: float = 0.5  #: an odometry increment longer than this per scan is doubted (metres) ...
    max_step_rad: float = math.radians(30.0)  #: ... or turning more than this per scan (radians)
    local: TfPlusConfig = TfPlusConfig()


def _far(a: Pose, b: Pose, metres: float, radians: float) -> bool:
    return a.distance_to(b) > metres or abs(float(wrap_angle(a.theta - b.theta))) > radians


class TfPlusTracker(LocalTracker):
    """``tf-plus-track``: ``tf-plus`` along a sequence with the two rules of the module notes.
    ``info`` of each step adds ``jump`` (a far answer was considered), ``kept`` (``"far"``,
    ``"near"`` or ``"still"``: which answer was taken) and ``doubted_odometry``."""

    name = "tf-plus-track"
    CONFIG = TfPlusTrackConfig

    def __init__(self, config: TfPlusTrackConfig | None = None, **overrides) -> None:
        self.config = resolve_params(TfPlusTrackConfig, config, overrides)
        super().__init__(TurningFunctionPlusMatcher(self.config.local))
        self.name = "tf-plus-track"
        self.near = TurningFunctionPlusMatcher(dataclasses.replace(self.config.local, grid=False))

    def warm(self, map: Map, laser: LaserSpec, ranges: np.ndarray, pose: Pose) -> None:
        super().warm(map, laser, ranges, pose)
        problem = Problem(map, laser, ranges, pose)
        self.near.prepare(problem)
        self.near.localize(problem)

    def _residual(self, matcher: TurningFunctionPlusMatcher, problem: Problem, est: Estimate) -> float:
        """The answer's selection objective (RMS residual, metres): the root of the cost
        ``tf-plus`` reports with it, or scored anew."""
        cost = est.info.get("cost")
        return math.sqrt(cost) if isinstance(cost, float) else matcher.score(problem, est.pose)

    def _answer(self, ranges: np.ndarray, guess: Pose, where: str) -> tuple[Problem | None, Estimate, float]:
        """``tf-plus``'s answer from ``guess`` and its residual (inf when it kept the guess)."""
        problem, est = self.answer(ranges, guess, where)
        if problem is None or est.info.get("status") == PREDICTED:
            return problem, est, math.inf
        return problem, est, self._residual(self.matcher, problem, est)

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        cfg = self.config
        pred = self.predict(odom_delta)
        problem, est, score = self._answer(ranges, pred, where)
        kept, jump = "far", False
        if problem is not None and _far(est.pose, pred, cfg.jump_gate_m, cfg.jump_gate_rad):
            jump = True
            near = self.near.localize(problem)
            if not near.declined:
                near_score = self._residual(self.near, problem, near)
                if not near_score > cfg.jump_ratio * score:
                    est, score, kept = near, near_score, "near"
        doubted = _far(Pose(), odom_delta, cfg.max_step_m, cfg.max_step_rad)
        if doubted and self.pose is not None:
            _, still, still_score = self._answer(ranges, self.pose, where)
            if still_score < score:
                est, score, kept = still, still_score, "still"
        self.pose = est.pose
        return Estimate(est.pose, est.converged, est.iterations, est.evaluations,
                        {**est.info, "jump": jump, "kept": kept, "doubted_odometry": doubted,
                         "score": score if math.isfinite(score) else None})
