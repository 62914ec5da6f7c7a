"""What the two AMCL trackers share: ``amcl`` (the port, :mod:`tfloc.baselines.amcl`) and
``amcl-wheel`` (:mod:`tfloc.baselines.amcl_wheel`). tfloc's own code around Nav2's filter (MIT,
as the rest of tfloc: neither a translation of nav2_amcl nor a use of the GPL-3.0 wheel), doing
what ``AmclNode`` (``nav2_amcl/src/amcl_node.cpp``) does around it. Metres, radians.

* :func:`amcl_grid`: the grid AMCL runs on, a grid map as given, a vector map rasterised at 5 cm
  (as a user exports it for Nav2).
* :func:`resolve_config`: a tracker's parameters resolved and checked, the particle and beam
  counts Nav2 would mend or skip refused before a run.
* :class:`ScanLimits`: a scan as ``AmclNode::updateFilter`` hands it to the sensor model.
* :func:`carry`: a map pose carried by the odometry (Nav2's map→odom transform): between filter
  updates the estimate is the last published pose carried so, and a start or ``reset`` pose is
  carried so up to the next scan (``handleInitialPose``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose
from tfloc.errors import InvalidProblemError, ParameterError
from tfloc.maps.build import rasterize
from tfloc.maps.cache import cached
from tfloc.maps.grid import GridMap

#: Grid resolution (m) a vector map is rasterised at, as a user would export it for Nav2
VECTOR_MAP_RESOLUTION = 0.05
C = TypeVar("C")


def amcl_grid(map_: Map) -> GridMap:
    """The grid AMCL runs on: ``map_`` itself if it is a grid, else rasterised at 5 cm (cached per map)."""
    if isinstance(map_, GridMap):
        return map_
    return cached(map_, ("amcl-grid", VECTOR_MAP_RESOLUTION), lambda: rasterize(map_, VECTOR_MAP_RESOLUTION))


def resolve_config(kind: type[C], config: C | None, overrides: dict[str, object]) -> C:
    """An AMCL tracker's parameters: ``config`` (or ``kind()``) with ``overrides``, checked by
    :func:`~tfloc.core.params.resolve_params`; then refused, naming the parameters, what Nav2 would
    mend or skip quietly: ``min_particles`` above ``max_particles`` (Nav2 warns and raises
    ``max_particles``) and ``max_beams`` below 2 (the models step by ``(n − 1) / (max_beams − 1)``:
    Nav2 then skips the sensor update without a word, the wheel divides by zero)."""
    c = resolve_params(kind, config, overrides)
    if c.min_particles > c.max_particles:
        raise ParameterError(f"min_particles ({c.min_particles}) must not exceed max_particles "
                             f"({c.max_particles})", ("min_particles", "max_particles"))
    if c.max_beams < 2:
        raise ParameterError(f"max_beams must be >= 2, got {c.max_beams}", ("max_beams",))
    return c


@dataclass(frozen=True)
class ScanLimits:
    """The range limits ``AmclNode::updateFilter`` applies to a scan of ``laser`` (metres).

    Attributes:
        beams: the laser's beam count; a scan of another length is refused.
        no_return: the laser's max range: a reading at or beyond it, inf or NaN is no return, +inf
            (as a REP 117 driver reports it; NaN would poison the beam model's weights).
        range_min: ``laser_min_range``, at least 0 (tfloc's laser reports no minimum range):
            readings at or below become ``range_max`` (Nav2: "amcl doesn't (yet) have a concept of
            min range").
        range_max: ``laser_max_range`` when > 0 and below the laser's, else the laser's max range:
            the sensor models' cap.
    """

    beams: int
    no_return: float
    range_min: float
    range_max: float

    @classmethod
    def of(cls, laser: LaserSpec, laser_max_range: float, laser_min_range: float) -> ScanLimits:
        """The limits of ``laser`` under Nav2's ``laser_max_range`` and ``laser_min_range``."""
        return cls(laser.n_beams, float(laser.max_range), max(laser_min_range, 0.0),
                   float(min(laser.max_range, laser_max_range) if laser_max_range > 0 else laser.max_range))

    def apply(self, ranges: np.ndarray, where: str) -> np.ndarray:
        """``ranges`` ``(beams,)`` as the sensor model gets them (contiguous float64); ``where``
        names the scan in the error for a scan of another length."""
        r = np.asarray(ranges, dtype=float)
        if r.shape != (self.beams,):
            raise InvalidProblemError(f"{where}: amcl: scan has {r.size} ranges, the laser {self.beams} beams")
        with np.errstate(invalid="ignore"):
            r = np.where(np.isfinite(r) & (r < self.no_return), r, np.inf)
            return np.ascontiguousarray(np.where(r <= self.range_min, self.range_max, r))


def carry(pose: Pose, at: Pose, odom: Pose) -> Pose:
    """``pose``, the map pose when the odometry read ``at``, carried by the odometry to ``odom``."""
    return pose.compose(at.between(odom))
