"""Tracking: a localizer run continuously along a sequence, each scan from the last estimate
composed with the odometry since then.

A :class:`Tracker` is started once at the robot's starting pose and then stepped scan by scan
with the scan and the odometry increment (the relative motion the wheels measured since the
previous scan, in the robot's frame of the previous scan). Filters that keep a belief (AMCL)
implement it directly; every single-scan matcher becomes one through :class:`LocalTracker`:

    guess(k) = estimate(k−1) ⊕ (odom(k−1)⁻¹ · odom(k))

and a matcher that declines (or gives no finite pose) keeps the prediction as its estimate, the
step's ``info["status"]`` saying so. Units: metres, radians, seconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from tfloc.errors import InvalidProblemError

from .laser import LaserSpec
from .map import Map
from .params import Configured, resolve_params
from .pose import Pose
from .problem import Estimate, Problem

#: ``info["status"]`` of a step whose estimate is the prediction (the matcher declined)
PREDICTED = "predicted"
#: ``info[START_KEY] == GLOBAL_START`` on a tracker's first step: it started without a pose
#: (ignoring the one the harness passed), so its first scans are a global search
START_KEY, GLOBAL_START = "start", "global"


@runtime_checkable
class Tracker(Protocol):
    """What the harness needs of a localizer that runs along a sequence. The tracker owns its
    belief: it says what it expects before a scan (``predict``), takes the scan (``step``) and
    can be put back at a pose when a step raised (``reset``). It may also define
    ``warm(map, laser, ranges, pose)``: untimed work the harness asks for before ``start``
    (compiling kernels, map-only structures) with the first scan and the start pose."""

    name: str

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        """Begin a sequence on ``map`` at the robot's starting ``pose`` (world frame)."""
        ...

    def predict(self, odom_delta: Pose) -> Pose:
        """The pose the next ``step`` starts from, given the odometry increment (no state
        change): the guess a row records as ``init_*``."""
        ...

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        """One scan: ``ranges`` (metres), ``odom_delta`` the odometry increment since the last
        step (metres/radians, in the robot frame of the previous scan), ``stamp`` seconds;
        ``where`` names the scan in messages (``file:line``). An estimate that keeps the
        prediction says so in ``info["status"]`` (:data:`PREDICTED`)."""
        ...

    def reset(self, pose: Pose) -> None:
        """Put the belief at ``pose`` (the harness's prediction after a step raised)."""
        ...


def is_tracker(obj: object) -> bool:
    """Whether ``obj`` is a native tracker (``start``/``step``), not a single-scan matcher."""
    return callable(getattr(obj, "step", None)) and callable(getattr(obj, "start", None))


def has_single_scan_mode(obj: object) -> bool:
    """Whether ``obj`` localizes single scans (``localize``). A native tracker without it (AMCL)
    runs on sequence datasets only: single-scan runs leave it out with one line."""
    return callable(getattr(obj, "localize", None))


def kept_prediction(est: Estimate) -> bool:
    """Whether a tracker's step kept its prediction (the matcher declined, or the prediction
    posed no problem): such a row is ``failed``."""
    return est.info.get("status") == PREDICTED


class LocalTracker:
    """A single-scan matcher run as a tracker: each scan is localized from the prediction
    (last estimate ⊕ odometry increment); a declined scan, or a prediction that poses no
    problem (it left the map), keeps the prediction."""

    def __init__(self, matcher) -> None:
        self.matcher = matcher
        self.name = getattr(matcher, "name", type(matcher).__name__)
        self._map: Map | None = None
        self._laser: LaserSpec | None = None
        self.pose: Pose | None = None

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        self._map, self._laser, self.pose = map, laser, pose

    def warm(self, map: Map, laser: LaserSpec, ranges: np.ndarray, pose: Pose) -> None:
        """Untimed: the matcher's map-only work (``prepare``), one ``score`` and one
        ``localize`` of the first scan from ``pose`` (numba kernels compiled or loaded)."""
        problem = Problem(map, laser, ranges, pose)
        prepare = getattr(self.matcher, "prepare", None)
        if prepare is not None:
            prepare(problem)
        if callable(getattr(self.matcher, "score", None)):
            self.matcher.score(problem, pose)
        self.matcher.localize(problem)

    def predict(self, odom_delta: Pose) -> Pose:
        """The guess for the next scan: the last estimate composed with ``odom_delta``."""
        if self.pose is None:
            raise RuntimeError("LocalTracker.predict before start")
        return self.pose.compose(odom_delta)

    def answer(self, ranges: np.ndarray, guess: Pose, where: str = "scan") -> tuple[Problem | None, Estimate]:
        """The matcher's answer to the scan from ``guess``, and the problem it answered; the
        guess itself (:data:`PREDICTED`) when the matcher declines, or when the guess poses no
        problem (problem ``None``, ``info["reason"]`` says why)."""
        try:
            problem = Problem(self._map, self._laser, ranges, guess, where=where)
        except InvalidProblemError as exc:
            return None, Estimate(guess, False, info={"status": PREDICTED, "reason": str(exc)[:200]})
        return problem, self.answer_to(problem)

    def answer_to(self, problem: Problem) -> Estimate:
        """The matcher's answer to ``problem`` (posed from a guess), or the guess itself
        (:data:`PREDICTED`) when the matcher declines."""
        est = self.matcher.localize(problem)
        if est.declined:
            est = Estimate(problem.initial, False, est.iterations, est.evaluations,
                           {**est.info, "status": PREDICTED})
        return est

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        _, est = self.answer(ranges, self.predict(odom_delta), where)
        self.pose = est.pose
        return est

    def reset(self, pose: Pose) -> None:
        """Put the estimate at ``pose`` (e.g. the prediction after a matcher raised)."""
        self.pose = pose


class ConfiguredTracker(LocalTracker):
    """A :class:`LocalTracker` configured by one dataclass, ``CONFIG``, as a
    :class:`~tfloc.core.params.Configured` matcher is: ``Tracker(config=None, **overrides)`` sets
    ``self.config`` through :func:`~tfloc.core.params.resolve_params`, runs the single-scan matcher
    :meth:`matcher_of` builds from it, and keeps the class's ``name`` (not the matcher's)."""

    CONFIG: ClassVar[type]
    name: str

    def __init__(self, config: Any = None, **overrides: Any) -> None:
        self.config = resolve_params(self.CONFIG, config, overrides)
        super().__init__(self.matcher_of(self.config))
        self.name = type(self).name

    def matcher_of(self, config: Any) -> Any:
        """The single-scan matcher this tracker runs, made from its resolved ``config``."""
        raise NotImplementedError


def as_tracker(obj: object) -> Tracker:
    """``obj`` itself if it is a tracker (or answers whole sequences: an external program,
    :func:`tfloc.core.external.is_batch_tracker`), else a :class:`LocalTracker` around the
    matcher."""
    return obj if is_tracker(obj) or callable(getattr(obj, "run_batch", None)) else LocalTracker(obj)


@dataclass(frozen=True)
class NoParameters:
    """The configuration of a matcher that takes none."""


class DeadReckoning(Configured):
    """``odometry``: the prediction alone, the floor of every tracking table. Run along a
    sequence (:class:`LocalTracker`) it composes the odometry from the start pose (dead
    reckoning); on a single scan it answers its initial guess unchanged. It has no objective
    (no ``score``) and takes no parameter."""

    CONFIG = NoParameters
    name = "odometry"
    METHOD = None  # (tfloc.core.traits)
    kind = "tracker"  # (core.matcher.TRACKER: meant for sequences)

    def localize(self, problem: Problem) -> Estimate:
        return Estimate(problem.initial, True)


REGISTRY = {"odometry": {"class": "DeadReckoning", "docs": "tracking.md", "summary": (
    "a **tracker**: dead reckoning, the prediction alone (the start pose composed with the "
    "odometry); the floor of every tracking table; on a single scan it answers its guess "
    "unchanged")}}
