"""The question every matcher answers (:class:`Problem`) and its answer (:class:`Estimate`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from tfloc.errors import InvalidProblemError, TflocError

from .laser import LaserSpec, _scan_faults
from .pose import Pose

if TYPE_CHECKING:
    from tfloc.core.map import Map


def check_ranges(ranges: Any, laser: LaserSpec, where: str = "scan",
                 error: type[TflocError] = InvalidProblemError) -> np.ndarray:
    """Validate one scan's ranges (metres) against ``laser`` and return them as a float array.

    The one range rule of tfloc (scan files, bags and the Python API all come here):
    ``inf``/``nan``/≥ max_range mean *no return* and are allowed; a wrong beam count, a negative
    range or a scan with no return at all raise ``error`` naming ``where`` (e.g. ``file:line``).
    """
    try:
        r = np.asarray(ranges, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise error(f"{where}: ranges are not numeric ({exc})") from None
    if r.size != laser.n_beams:
        raise error(f"{where}: {r.size} ranges, expected {laser.n_beams} "
                    f"(laser {math.degrees(laser.fov):g}°/{math.degrees(laser.resolution):g}°)")
    negative, returns = _scan_faults(r, float(laser.max_range))   # one compiled pass
    if negative >= 0:
        raise error(f"{where}: negative range {r[negative]:g} at beam {negative}")
    if not returns:
        raise error(f"{where}: scan has no return at all (every range inf/nan/≥ max_range)")
    return r


@dataclass(frozen=True, eq=False)
class Problem:
    """Given a map, a laser spec, one real scan (RSD) and an initial pose guess (VP): where is the robot?

    Attributes:
        map: the known map (:class:`~tfloc.core.map.Map`).
        laser: the scanner that took ``ranges``.
        ranges: the real scan, metres, shape ``(laser.n_beams,)``; inf/nan/≥ max_range = no return.
        initial: the initial pose guess (VP), metres/radians, world frame; ``None`` poses a
            *global* problem (no guess: the answer is searched over the whole map), which only
            matchers that declare ``solves_global = True`` take (:func:`tfloc.core.matcher.check_solvable`).
    """

    map: Map
    laser: LaserSpec
    ranges: np.ndarray
    initial: Pose | None
    where: str = "scan"

    @property
    def is_global(self) -> bool:
        """No initial guess: the pose is searched over the whole map."""
        return self.initial is None

    def __post_init__(self) -> None:
        object.__setattr__(self, "ranges", check_ranges(self.ranges, self.laser, self.where))
        if self.initial is None:
            return
        if not self.initial.is_finite():
            raise InvalidProblemError(f"{self.where}: initial pose is not finite: {self.initial}")
        if not bool(self.map.in_bounds(np.array([[self.initial.x, self.initial.y]]))[0]):
            raise InvalidProblemError(
                f"{self.where}: initial pose ({self.initial.x:.3f}, {self.initial.y:.3f}) lies outside the map")

    def every(self, k: int, laser: LaserSpec | None = None) -> Problem:
        """The same question on every ``k``-th beam of the scan (``laser``: ``self.laser.every(k)``,
        passed in to share one object across scans). Only the beams kept are checked again (some
        must return); the guess was checked when this problem was made."""
        laser = self.laser.every(k) if laser is None else laser
        ranges = check_ranges(np.ascontiguousarray(self.ranges[::k]), laser, self.where)
        thinned = object.__new__(Problem)
        for name, value in (("map", self.map), ("laser", laser), ("ranges", ranges),
                            ("initial", self.initial), ("where", self.where)):
            object.__setattr__(thinned, name, value)
        return thinned

    @property
    def points(self) -> np.ndarray:
        """The real scan as points in the sensor frame (Eq. 4), no-return beams dropped."""
        return self.laser.to_points(self.ranges)


#: ``info["status"]`` of an estimate whose matcher declined to answer
NO_ANSWER = "no-answer"


@dataclass(frozen=True)
class Estimate:
    """A matcher's answer.

    Attributes:
        pose: the estimated robot pose (metres, radians).
        converged: whether the matcher's own stopping rule was met (not whether it is right).
        iterations: outer iterations of the method.
        evaluations: objective evaluations (for ``tf``: turning-function cost evaluations).
        info: method-specific extras (JSON-serialisable values).
        hypotheses: a global matcher's ranked answers, best first (``pose`` is the first); local
            matchers leave it empty. The harness scores the first five (top-5 success).
    """

    pose: Pose
    converged: bool
    iterations: int = 0
    evaluations: int = 0
    info: dict[str, Any] = field(default_factory=dict)
    hypotheses: tuple[Pose, ...] = ()

    @property
    def declined(self) -> bool:
        """The matcher gave no answer: it said so (``info["status"] == "no-answer"``) or its pose
        is not finite. The one rule: a declined estimate is a ``failed`` row, and a tracker
        keeps its prediction instead."""
        return self.info.get("status") == NO_ANSWER or not self.pose.is_finite()
