"""The :class:`Map` protocol: what every map (vector or grid) offers to matchers and the harness."""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from .laser import LaserSpec
from .pose import Pose


def as_pose_array(poses: Pose | np.ndarray | list) -> tuple[np.ndarray, bool]:
    """Normalise one :class:`Pose` or an ``(N, 3)`` array of poses to ``(N, 3)``; flag if single."""
    if isinstance(poses, Pose):
        return poses.as_array()[None, :], True
    arr = np.asarray(poses, dtype=float)
    if arr.ndim == 1:
        return arr.reshape(1, 3), True
    return arr.reshape(-1, 3), False


@runtime_checkable
class Map(Protocol):
    """A known 2D map, in metres, world frame."""

    def raycast(self, poses: Pose | np.ndarray, laser: LaserSpec) -> np.ndarray:
        """The virtual sensor (VSD): ranges (metres) seen from one pose ``(n_beams,)`` or a batch
        of ``(N, 3)`` poses ``(N, n_beams)``. No hit within ``laser.max_range`` gives ``inf``."""
        ...

    def is_free(self, xy: np.ndarray, clearance: float = 0.0) -> np.ndarray:
        """Boolean mask, shape ``(N,)``: which ``(N, 2)`` points lie in free space, at least
        ``clearance`` metres from any wall or obstacle."""
        ...

    def in_bounds(self, xy: np.ndarray) -> np.ndarray:
        """Boolean mask: which ``(N, 2)`` points lie inside the mapped area (walls included)."""
        ...

    def sample_points(self, spacing: float) -> tuple[np.ndarray, np.ndarray]:
        """The map's geometry as points every ``spacing`` metres with unit normals, both ``(M, 2)``."""
        ...

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` in metres."""
        ...
