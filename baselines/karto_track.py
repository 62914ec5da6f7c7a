"""``karto-gated``: ``karto`` along a sequence as slam_toolbox's localization mode runs it: a scan is
matched only after the robot has moved enough; between, the pose is the last one carried by the
odometry (slam_toolbox publishes map→odom from the last processed scan).

The gate is slam_toolbox's ``SlamToolbox::shouldProcessScan`` (``slam_toolbox_common.cpp``), which
``LocalizationSlamToolbox::laserCallback`` asks before handing a scan to Karto:

* the first scan passes; Karto does not match it (``Mapper::ProcessLocalization`` corrects a scan
  only when there is a last one): its pose is the start;
* a scan whose counter is not a multiple of ``throttle_scans`` is dropped;
* one less than ``minimum_time_interval`` seconds after the last processed scan is dropped;
* one whose odometry moved less than √0.8 · ``minimum_travel_distance`` since then, or whose
  counter is below 5, is dropped ("within 10 % for correction error");
* Karto's own ``Mapper::HasMovedEnough`` then passes every scan that did not drop: its first test
  is the same time interval. ``minimum_travel_heading`` is read there but never decides, so a
  turn in place is not matched (slam_toolbox's ROS 2 code; the gate tests translation only).

A matched scan starts from the prediction (last estimate ⊕ odometry increment), as Karto's
``ProcessLocalization`` starts from the last correction applied to the odometric pose. Units:
metres, seconds. Values and sources: ``docs/baselines/karto.md`` (Tracking configuration).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate
from tfloc.core.tracker import ConfiguredTracker
from tfloc.core.traits import Confidence

from .karto import Config as KartoConfig
from .karto import KartoMatcher


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`KartoGatedTracker`: slam_toolbox's gate, then Karto's own (``local``)."""

    RULES: ClassVar[dict] = {">= 0": ("minimum_travel_distance", "minimum_travel_heading",
                                      "minimum_time_interval"),
                             ">= 1": ("throttle_scans",)}

    minimum_travel_distance: float = 0.5  #: match after the odometry moved √0.8 × this (metres)
    minimum_travel_heading: float = 0.5  #: Karto's heading test (radians; never decides, see the notes)
    minimum_time_interval: float = 0.5  #: ... and at least this long after the last match (seconds)
    throttle_scans: int = 1  #: only every this many-th scan is considered
    local: KartoConfig = field(default_factory=KartoConfig)


class KartoGatedTracker(ConfiguredTracker):
    """``karto`` matched only when slam_toolbox's gate passes (see the module docstring). ``info``
    of each step: ``matched`` (whether Karto ran) and ``travel_m`` (odometry since the last match)."""

    name = "karto-gated"
    METHOD = "karto"  # (tfloc.core.traits)
    CONFIDENCE = Confidence("response", True, "Karto's correlation response (the last matched scan's between matches)")
    CONFIG = Config

    def matcher_of(self, config: Config) -> KartoMatcher:
        return KartoMatcher(config.local)

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        super().__init__(config, **overrides)
        self._reset_gate()

    def _reset_gate(self) -> None:
        self._count = 0
        self._since = Pose()  # odometry since the last processed scan
        self._last_stamp: float | None = None

    def start(self, map, laser, pose: Pose) -> None:  # noqa: ANN001 - the Tracker protocol's
        super().start(map, laser, pose)
        self._reset_gate()

    def _passes(self, stamp: float) -> bool:
        """slam_toolbox's ``shouldProcessScan`` (the module notes); counts the scan."""
        c = self.config
        self._count += 1
        if self._last_stamp is None:
            return True
        if self._count % c.throttle_scans != 0 or stamp - self._last_stamp < c.minimum_time_interval:
            return False
        dist2 = self._since.x**2 + self._since.y**2
        return not (dist2 < 0.8 * c.minimum_travel_distance**2 or self._count < 5)

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        pred = self.predict(odom_delta)
        self._since = self._since.compose(odom_delta)
        first = self._last_stamp is None
        if not self._passes(stamp):
            self.pose = pred
            return Estimate(pred, True, info={"matched": False, "travel_m": math.hypot(self._since.x, self._since.y)})
        travel = math.hypot(self._since.x, self._since.y)
        self._since, self._last_stamp = Pose(), stamp
        if first:  # Karto keeps its first scan where it is put
            self.pose = pred
            return Estimate(pred, True, info={"matched": False, "travel_m": travel})
        _, est = self.answer(ranges, pred, where)
        self.pose = est.pose
        return Estimate(est.pose, est.converged, est.iterations, est.evaluations,
                        {**est.info, "matched": True, "travel_m": travel})

    def reset(self, pose: Pose) -> None:
        self.pose = pose


REGISTRY = {"karto-gated": {"class": "KartoGatedTracker", "docs": "baselines/karto.md", "summary": (
    "a **tracker**: `karto` matched only when slam_toolbox's `shouldProcessScan` gate passes "
    "(between, the odometry carries the pose). Its package's shipped values are the preset "
    "`karto-track`")}}
