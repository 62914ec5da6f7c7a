"""``tf-plus-track``: ``tf-plus`` run along a sequence that weighs the odometry's prediction when
the scan cannot tell two places apart, and searches little where the prediction is trusted.

Single-scan ``tf-plus`` searches ±``search_radius`` around its guess and takes the pose whose
scan residual is lowest. Along a recording that is the right answer to a one-scan question and
the wrong one for a robot: where the geometry repeats (a corridor, a bare corner, people in
front of the laser) a pose metres away can explain the scan as well as the right one, and the
tracker jumps there. Three rules, each of them the robot's prior knowledge of its own motion:

1. **A jump must be earned.** An answer beyond ``jump_gate_m`` / ``jump_gate_rad`` of the
   prediction is kept only if it explains the scan ``jump_ratio`` times better (RMS residual,
   metres) than ``tf-plus`` without its position grid (the best pose *near* the prediction).
2. **An odometry increment the robot cannot have made is doubted.** An increment beyond
   ``max_step_m`` / ``max_step_rad`` per scan (an encoder that froze and caught up in one
   message) is also tried as no motion, from the last estimate; the better scoring answer wins.
3. **A trusted prediction is searched in a window of the odometry's noise.** After an answer that
   fits (its point-to-line residual ≤ ``widen_score``: ``tf-plus``'s selection cost without the
   see-through term, which only the choice among candidates needs) and for an increment not
   doubted, ``tf-plus`` searches ±``window_m`` / ±``window_rad`` (:func:`window_config`) instead
   of the protocol's window; an answer there that does not fit, or lies beyond the jump gate, is
   searched again as above. The window covers MIT CSAIL's per-scan corrections (99.9th
   percentile 0.26 m, 15.6°) and ``widen_score`` is the 98th percentile of its answers'
   point-to-line residuals (``docs/tracking.md``). The window and the fit read beams at least
   ``window_spacing`` apart (every other beam of a 0.5° scanner), as many as a 1° scanner has.

A prediction ``tf-plus`` cannot answer (too few returns) is kept, as for every single-scan
matcher run as a tracker (:class:`~tfloc.core.tracker.LocalTracker`). The true pose is never
read. Every value was chosen on the MIT CSAIL native sequence only (``docs/tracking.md``).
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
from tfloc.core.traits import Confidence
from tfloc.errors import InvalidProblemError

from .config import TfPlusConfig
from .matcher import TurningFunctionPlusMatcher
from .refine import _gates


@dataclass(frozen=True)
class TfPlusTrackConfig:
    """Parameters of ``tf-plus-track`` (metres, radians; ``local``: ``tf-plus``'s own)."""

    RULES: ClassVar[dict] = {"> 0": ("jump_gate_m", "jump_gate_rad", "max_step_m", "max_step_rad"),
                             ">= 0": ("window_m", "window_rad", "widen_score", "window_spacing"),
                             ">= 1": ("jump_ratio",)}

    jump_gate_m: float = 0.5  #: an answer farther than this from the prediction is a jump (metres) ...
    jump_gate_rad: float = math.radians(20.0)  #: ... or turned more than this (radians)
    jump_ratio: float = 1.5  #: a jump is kept only if the near answer's residual is this many times its own
    max_step_m: float = 0.5  #: an odometry increment longer than this per scan is doubted (metres) ...
    max_step_rad: float = math.radians(30.0)  #: ... or turning more than this per scan (radians)
    trusted_window: bool = True  #: search a trusted prediction's window first (False: the protocol's, every scan)
    window_m: float = 0.3  #: the trusted window's radius (metres) ...
    window_rad: float = math.radians(15.0)  #: ... and heading span (radians)
    widen_score: float = 0.04  #: an answer whose point-to-line residual (RMS, metres) is above this does not fit
    window_spacing: float = math.radians(1.0)  #: the window reads every k-th beam, the most k that keeps them this close (radians)
    local: TfPlusConfig = TfPlusConfig()


#: the trusted window's refinement: the last iterations of ``local``'s gate schedule (from 0.2 m
#: down), and its shortlist (its best coarse poses rescored on every point)
WINDOW_ITERATIONS, WINDOW_SHORTLIST = 4, 8


def window_config(cfg: TfPlusTrackConfig) -> TfPlusConfig:
    """``tf-plus`` in the trusted window: positions within ``window_m`` and headings within
    ``window_rad`` of the prediction (never more than ``local``'s own), no turning-function seeds
    (they look for headings far outside the window), one candidate refined from a shortlist of
    :data:`WINDOW_SHORTLIST` (the window holds about a hundred poses, not fifteen thousand) with
    the last :data:`WINDOW_ITERATIONS` gates of the refinement's schedule (the coarse pose is
    already within a lattice cell of the answer), and no see-through term in its cost (one
    candidate needs no selection: its cost is the point-to-line residual the fit is judged by);
    the rest is ``local``'s."""
    local, r = cfg.local, cfg.local.refinement
    iterations = min(WINDOW_ITERATIONS, r.iterations)
    refinement = dataclasses.replace(r, gate_start=float(_gates(r)[-iterations]), iterations=iterations)
    return dataclasses.replace(local, tf_seed=False, search_radius=min(cfg.window_m, local.search_radius),
                               heading_span=min(cfg.window_rad, local.heading_span), candidates=1,
                               shortlist=min(WINDOW_SHORTLIST, local.shortlist), refinement=refinement,
                               beam_check=False)


_STILL = Pose()  #: no motion: the odometry increment an increment is doubted against


def _far(a: Pose, b: Pose, metres: float, radians: float) -> bool:
    """Whether ``a`` lies more than ``metres`` from ``b`` or is turned more than ``radians``."""
    return a.distance_to(b) > metres or abs(wrap_angle(a.theta - b.theta)) > radians


class TfPlusTracker(LocalTracker):
    """``tf-plus-track``: ``tf-plus`` along a sequence with the rules of the module notes.
    ``info`` of each step adds ``widened`` (the trusted window's answer did not fit and the
    protocol's window was searched), ``jump`` (a far answer was considered), ``kept``
    (``"window"``, ``"far"``, ``"near"`` or ``"still"``: which answer was taken; ``"far"`` is the
    protocol's window's), ``doubted_odometry`` and ``score`` (the answer's point-to-line residual,
    metres: what the fit is judged by)."""

    name = "tf-plus-track"
    METHOD = "tf-plus"  # (tfloc.core.traits)
    CONFIDENCE = Confidence("score", False, "its answer's point-to-line residual (RMS, metres)")
    CONFIG = TfPlusTrackConfig

    def __init__(self, config: TfPlusTrackConfig | None = None, **overrides) -> None:
        self.config = resolve_params(TfPlusTrackConfig, config, overrides)
        super().__init__(TurningFunctionPlusMatcher(self.config.local))
        self.name = "tf-plus-track"
        self.near = TurningFunctionPlusMatcher(dataclasses.replace(self.config.local, grid=False))
        self.window = TurningFunctionPlusMatcher(window_config(self.config))
        self.trusted = False
        self.stride, self.window_laser = 1, None     # every beam until a scanner is known

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        super().start(map, laser, pose)
        self.trusted = False          # the first scan is searched in the protocol's window
        self._window_beams(laser)

    def _window_beams(self, laser: LaserSpec) -> None:
        """The beams the window reads: every ``stride``-th, the scanner ``window_laser`` (one
        object per sequence: ``tf-plus`` caches its plan by it)."""
        self.stride = max(1, int(self.config.window_spacing / laser.resolution + 1e-9))
        self.window_laser = laser.every(self.stride)

    def reset(self, pose: Pose) -> None:
        super().reset(pose)
        self.trusted = False

    def warm(self, map: Map, laser: LaserSpec, ranges: np.ndarray, pose: Pose) -> None:
        super().warm(map, laser, ranges, pose)
        self._window_beams(laser)
        problem = Problem(map, laser, ranges, pose)
        for matcher, asked in ((self.near, problem), (self.window, self._thinned(problem))):
            matcher.prepare(asked)
            matcher.localize(asked)

    def _residual(self, matcher: TurningFunctionPlusMatcher, problem: Problem, est: Estimate) -> float:
        """The answer's selection objective under ``matcher`` (RMS residual, metres): the root of
        the cost ``tf-plus`` reports with it, or scored anew."""
        cost = est.info.get("cost")
        return math.sqrt(cost) if isinstance(cost, float) else matcher.score(problem, est.pose)

    def _answer(self, ranges: np.ndarray, guess: Pose, where: str,
                problem: Problem | None = None) -> tuple[Problem | None, Estimate, float]:
        """``tf-plus``'s answer from ``guess`` (to ``problem`` where the step already posed it from
        there) and its residual (inf when it kept the guess)."""
        if problem is None:
            problem, est = self.answer(ranges, guess, where)
        else:
            est = self.answer_to(problem)
        if problem is None or est.info.get("status") == PREDICTED:
            return problem, est, math.inf
        return problem, est, self._residual(self.matcher, problem, est)

    def _thinned(self, problem: Problem) -> Problem:
        """``problem`` on the beams the window reads (:class:`~tfloc.core.problem.Problem.every`;
        it raises :class:`~tfloc.errors.InvalidProblemError` if none of them returns)."""
        return problem if self.stride == 1 else problem.every(self.stride, self.window_laser)

    def _fit(self, problem: Problem | None, est: Estimate) -> float:
        """How well an answer of the protocol's window fits (metres): its point-to-line residual
        on the window's beams, the trusted window's objective (inf when the guess was kept)."""
        if problem is None or est.info.get("status") == PREDICTED:
            return math.inf
        try:
            return self.window.score(self._thinned(problem), est.pose)
        except InvalidProblemError:
            return math.inf

    def _in_window(self, problem: Problem) -> tuple[Estimate | None, float]:
        """The trusted window's answer to ``problem`` (posed from the prediction) and its
        point-to-line residual, or ``None`` where it does not fit: no answer, a residual above
        ``widen_score`` or a pose beyond the jump gate."""
        cfg = self.config
        try:
            problem = self._thinned(problem)
        except InvalidProblemError:
            return None, math.inf
        est = self.window.localize(problem)
        if est.declined:
            return None, math.inf
        fit = self._residual(self.window, problem, est)
        if not fit <= cfg.widen_score or _far(est.pose, problem.initial, cfg.jump_gate_m, cfg.jump_gate_rad):
            return None, fit
        return est, fit

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        cfg = self.config
        pred = self.predict(odom_delta)
        doubted = _far(_STILL, odom_delta, cfg.max_step_m, cfg.max_step_rad)
        kept, jump, widened, est, problem = "window", False, False, None, None
        if self.trusted and not doubted:
            try:                # the step's one problem: the window's, and the wider search's
                problem = Problem(self._map, self._laser, ranges, pred, where=where)
            except InvalidProblemError:
                pass            # searched again below, which keeps the prediction and says why
            else:
                est, fit = self._in_window(problem)
            widened = est is None
        if est is None:
            kept = "far"
            problem, est, score = self._answer(ranges, pred, where, problem)
            if problem is not None and _far(est.pose, pred, cfg.jump_gate_m, cfg.jump_gate_rad):
                jump = True
                near = self.near.localize(problem)
                if not near.declined:
                    near_score = self._residual(self.near, problem, near)
                    if not near_score > cfg.jump_ratio * score:
                        est, score, kept = near, near_score, "near"
            if doubted and self.pose is not None:
                still_problem, still, still_score = self._answer(ranges, self.pose, where)
                if still_score < score:
                    problem, est, kept = still_problem, still, "still"
            fit = self._fit(problem, est)
        self.pose = est.pose
        self.trusted = cfg.trusted_window and fit <= cfg.widen_score
        return Estimate(est.pose, est.converged, est.iterations, est.evaluations,
                        {**est.info, "widened": widened, "jump": jump, "kept": kept,
                         "doubted_odometry": doubted, "score": fit if math.isfinite(fit) else None})


REGISTRY = {"tf-plus-track": {"class": "TfPlusTracker", "docs": "tracking.md", "summary": (
    "a **tracker**: `tf-plus` along a sequence that weighs the odometry's prediction when the"
    " scan is ambiguous (a jump must explain the scan 1.5 times better than the best pose "
    "near the prediction; an odometry increment the robot cannot have made is also tried as "
    "no motion; a trusted prediction is searched in a window of the odometry's noise, widened"
    " when the scan does not fit), chosen on the MIT CSAIL native log "
    "([docs/tracking.md](tracking.md))")}}
