"""Tracking with recovery: a local matcher run along a sequence that notices by its own score
that it is lost (a kidnapped robot, a bad start) and then asks a global matcher where it is.

Each scan is localized by the local matcher from the prediction (last estimate ⊕ odometry
increment, as :class:`tfloc.core.tracker.LocalTracker`) and scored by the local matcher's own
objective at its answer (``tf-plus``'s: the root mean square of the truncated per-beam
residuals, metres). After ``lost_after`` consecutive scans scoring above ``lost_score`` the
tracker is *lost*: the global matcher answers the scan without a guess, and its answer replaces
the local one if its score is lower and at most ``accept_score``; otherwise the tracker stays
lost and asks again at the next scan. The true pose is never read. Units: metres, radians.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem
from tfloc.core.tracker import LocalTracker
from tfloc.core.traits import Confidence
from tfloc.tfplus.matcher import TfPlusConfig, TurningFunctionPlusMatcher

from .matcher import TfGlobalConfig, TurningFunctionGlobalMatcher


@dataclass(frozen=True)
class RecoveryConfig:
    """When a tracker counts itself lost and takes a global answer (metres of the local
    matcher's score).

    Attributes:
        lost_score: a scan scoring above this is a bad match ...
        lost_after: ... and this many in a row make the tracker lost.
        accept_score: a global answer is taken only if its score is at most this (and lower
            than the local answer's).
    """

    RULES: ClassVar[dict] = {"> 0": ("lost_score", "accept_score"), ">= 1": ("lost_after",)}

    lost_score: float = 0.05
    lost_after: int = 2
    accept_score: float = 0.05


class RecoveringTracker(LocalTracker):
    """A local matcher as a tracker (:class:`~tfloc.core.tracker.LocalTracker`), with a global
    matcher for when it is lost (see the module notes). ``info`` of each step: ``score`` (the
    answer's), ``lost`` (the tracker counted itself lost at this scan), ``relocalized`` (the
    global answer was taken)."""

    def __init__(self, local, global_, config: RecoveryConfig | None = None, **overrides) -> None:
        super().__init__(local)
        self.global_ = global_
        self.config = resolve_params(RecoveryConfig, config, overrides)
        self.name = f"{getattr(local, 'name', 'local')}+{getattr(global_, 'name', 'global')}"
        self.bad = 0

    @property
    def local(self):
        """The local matcher (tracking from the prediction)."""
        return self.matcher

    def prepare(self, problem: Problem) -> None:
        """Map-only work of both matchers (``tf-global``'s place index), untimed (``warm`` calls
        it before the sequence; else the first relocalization builds the index inside a timed
        step)."""
        for m in (self.local, self.global_):
            prepare = getattr(m, "prepare", None)
            if prepare is not None and (problem.initial is not None or m is self.global_):
                prepare(problem)

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        super().start(map, laser, pose)
        self.bad = 0

    def step(self, ranges, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        cfg = self.config
        problem, est = self.answer(ranges, self.predict(odom_delta), where)
        score = float(self.local.score(problem, est.pose)) if problem is not None else float("inf")
        self.bad = self.bad + 1 if not score <= cfg.lost_score else 0
        lost = self.bad >= cfg.lost_after
        relocalized = False
        if lost:
            anywhere = Problem(self._map, self._laser, ranges, None, where=where)
            found = self.global_.localize(anywhere)
            if not found.declined:
                g_score = float(self.global_.score(problem if problem is not None else anywhere, found.pose))
                if g_score <= cfg.accept_score and g_score < score:
                    est = Estimate(found.pose, found.converged, found.iterations,
                                   est.evaluations + found.evaluations,
                                   {**found.info, "status": "ok"}, found.hypotheses)
                    score, relocalized, self.bad = g_score, True, 0
        self.pose = est.pose
        return Estimate(est.pose, est.converged, est.iterations, est.evaluations,
                        {**est.info, "score": score, "lost": lost, "relocalized": relocalized},
                        est.hypotheses)


@dataclass(frozen=True)
class TfPlusRecoverConfig:
    """Parameters of ``tf-plus-recover``: the recovery rule (:class:`RecoveryConfig`'s fields,
    metres of tf-plus's score), ``tf-plus``'s (``local``) and ``tf-global``'s (``relocalizer``)."""

    RULES: ClassVar[dict] = RecoveryConfig.RULES

    lost_score: float = 0.02
    lost_after: int = 2
    accept_score: float = 0.02
    local: TfPlusConfig = TfPlusConfig()
    relocalizer: TfGlobalConfig = TfGlobalConfig()


class TfPlusRecoverTracker(RecoveringTracker):
    """``tf-plus-recover``: ``tf-plus`` tracking, ``tf-global`` when lost (module notes), the
    registered tracker. Its rule's values were chosen on the development sequence
    ``seq-kidnap-dev`` (``docs/kidnap.md``). A tracker only: no single-scan ``localize``."""

    name = "tf-plus-recover"
    METHOD = "tf-plus"  # (tfloc.core.traits)
    CONFIDENCE = Confidence("score", False, "its answer's point-to-line residual (RMS, metres), its lost test's input")
    CONFIG = TfPlusRecoverConfig

    def __init__(self, config: TfPlusRecoverConfig | None = None, **overrides) -> None:
        cfg = resolve_params(TfPlusRecoverConfig, config, overrides)
        super().__init__(TurningFunctionPlusMatcher(cfg.local), TurningFunctionGlobalMatcher(cfg.relocalizer),
                         RecoveryConfig(cfg.lost_score, cfg.lost_after, cfg.accept_score))
        self.name, self.config = "tf-plus-recover", cfg   # (the rule's fields are its own)

    def warm(self, map: Map, laser: LaserSpec, ranges, pose: Pose) -> None:
        """Untimed, before the sequence: the map-only work of both matchers (``tf-global``'s
        place index, ``tf-plus``'s map view) and ``tf-plus``'s compiled kernels, on the first
        scan from the start pose (never the truth)."""
        super().warm(map, laser, ranges, pose)
        self.prepare(Problem(map, laser, ranges, None))


REGISTRY = {"tf-plus-recover": {"class": "TfPlusRecoverTracker", "docs": "kidnap.md", "summary": (
    "a **tracker**: `tf-plus` from the prediction; when `tf-plus`'s own score says lost (2 "
    "scans above 2 cm RMS residual, chosen on `seq-kidnap-dev`) it asks `tf-global` (no "
    "guess) and takes its answer if it scores better; kidnapped sequences: "
    "`benchmarks/kidnap.toml`, [docs/kidnap.md](kidnap.md)")}}
