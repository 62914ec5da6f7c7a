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
from typing import Protocol, runtime_checkable

import numpy as np

from .laser import LaserSpec
from .map import Map
from .params import Configured
from .pose import Pose
from .problem import Estimate, Problem

#: ``info["status"]`` of a step whose estimate is the prediction (the matcher declined)
PREDICTED = "predicted"


@runtime_checkable
class Tracker(Protocol):
    """What the harness needs of a localizer that runs along a sequence."""

    name: str

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        """Begin a sequence on ``map`` at the robot's starting ``pose`` (world frame)."""
        ...

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float) -> Estimate:
        """One scan: ``ranges`` (metres), ``odom_delta`` the odometry increment since the last
        step (metres/radians, in the robot frame of the previous scan), ``stamp`` seconds."""
        ...


def is_tracker(obj: object) -> bool:
    """Whether ``obj`` is a native tracker (``start``/``step``), not a single-scan matcher."""
    return callable(getattr(obj, "step", None)) and callable(getattr(obj, "start", None))


def has_single_scan_mode(obj: object) -> bool:
    """Whether ``obj`` localizes single scans (``localize``). A native tracker without it (AMCL)
    runs on sequence datasets only: single-scan runs leave it out with one line."""
    return callable(getattr(obj, "localize", None))


class LocalTracker:
    """A single-scan matcher run as a tracker: each scan is localized from the prediction
    (last estimate ⊕ odometry increment); a declined scan keeps the prediction."""

    def __init__(self, matcher) -> None:
        self.matcher = matcher
        self.name = getattr(matcher, "name", type(matcher).__name__)
        self._map: Map | None = None
        self._laser: LaserSpec | None = None
        self.pose: Pose | None = None

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        self._map, self._laser, self.pose = map, laser, pose

    def predict(self, odom_delta: Pose) -> Pose:
        """The guess for the next scan: the last estimate composed with ``odom_delta``."""
        if self.pose is None:
            raise RuntimeError("LocalTracker.step before start")
        return self.pose.compose(odom_delta)

    def answer(self, ranges: np.ndarray, guess: Pose, where: str = "scan") -> tuple[Problem, Estimate]:
        """The matcher's answer to the scan from ``guess`` (the prediction, kept when it
        declines), and the problem it answered."""
        problem = Problem(self._map, self._laser, ranges, guess, where=where)
        est = self.matcher.localize(problem)
        if est.info.get("status") == "no-answer" or not est.pose.is_finite():
            est = Estimate(guess, False, est.iterations, est.evaluations,
                           {**est.info, "status": PREDICTED})
        return problem, est

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        _, est = self.answer(ranges, self.predict(odom_delta), where)
        self.pose = est.pose
        return est

    def reset(self, pose: Pose) -> None:
        """Put the estimate at ``pose`` (e.g. the prediction after a matcher raised)."""
        self.pose = pose


def as_tracker(obj: object) -> Tracker:
    """``obj`` itself if it is a tracker, else a :class:`LocalTracker` around the matcher."""
    return obj if is_tracker(obj) else LocalTracker(obj)


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

    def localize(self, problem: Problem) -> Estimate:
        return Estimate(problem.initial, True)
