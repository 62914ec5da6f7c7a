"""SE(2) helpers shared by the baselines: pose ↔ homogeneous matrices and projection onto SE(2)."""

from __future__ import annotations

import math

import numpy as np

from tfloc.core.pose import Pose, wrap_angle


def pose_to_matrix(pose: Pose, dim: int = 3) -> np.ndarray:
    """The homogeneous transform of ``pose``: ``(3, 3)`` for ``dim=2``/``3``, ``(4, 4)`` for ``dim=4``.

    A 4x4 transform embeds the pose in the plane z = 0 (rotation about z).
    """
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    n = 4 if dim == 4 else 3
    t = np.eye(n)
    t[:2, :2] = ((c, -s), (s, c))
    t[:2, n - 1] = (pose.x, pose.y)
    return t


def matrix_to_pose(t: np.ndarray) -> Pose:
    """Project a ``(3, 3)`` planar or ``(4, 4)`` spatial rigid/similarity transform onto SE(2).

    The translation keeps its x, y part (z is dropped); the rotation is the angle of the upper-left
    2x2 block's closest rotation (its polar factor), which for a rotation about a tilted axis or a
    scaled rotation is ``atan2(R10 - R01, R00 + R11)``.
    """
    t = np.asarray(t, dtype=float)
    n = t.shape[0]
    r = t[:2, :2]
    theta = math.atan2(r[1, 0] - r[0, 1], r[0, 0] + r[1, 1])
    return Pose(float(t[0, n - 1]), float(t[1, n - 1]), float(wrap_angle(theta)))


def embed_z0(points: np.ndarray) -> np.ndarray:
    """``(N, 2)`` planar points (or vectors) → ``(N, 3)`` with z = 0, float64, C-contiguous."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return np.ascontiguousarray(np.column_stack((p, np.zeros(len(p)))))
