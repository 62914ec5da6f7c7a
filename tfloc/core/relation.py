"""A ground-truth relation (Kümmerle et al. 2009): the robot's pose at one time seen from its
pose at another (metres, radians); :mod:`tfloc.io.relations` reads them."""

from __future__ import annotations

from dataclasses import dataclass

from .pose import Pose


@dataclass(frozen=True)
class Relation:
    """One relation: ``delta`` is the pose at ``t2`` seen from the pose at ``t1`` (m, rad)."""

    t1: float
    t2: float
    delta: Pose
    line: int
