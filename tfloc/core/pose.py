"""SE(2) poses (metres, radians) and the angle difference of the paper's Eq. 6."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def wrap_angle(a: float | np.ndarray) -> float | np.ndarray:
    """Wrap an angle (radians) into [-pi, pi). One float is wrapped in plain floats (Python's
    float ``%`` is numpy's float64 remainder: the same value bit for bit, and much cheaper)."""
    if isinstance(a, float):
        return float((a + math.pi) % (2.0 * math.pi) - math.pi)
    w = (np.asarray(a, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi
    return float(w) if w.ndim == 0 else w


def angdiff(a: float | np.ndarray, b: float | np.ndarray) -> float | np.ndarray:
    """Eq. 6: the signed difference ``a - b`` of two angles (radians), wrapped into [-pi, pi]."""
    d = np.arctan2(np.sin(np.subtract(a, b)), np.cos(np.subtract(a, b)))
    return float(d) if np.ndim(d) == 0 else d


@dataclass(frozen=True, slots=True)
class Pose:
    """A 2D pose: position ``(x, y)`` in metres and heading ``theta`` in radians."""

    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0

    @classmethod
    def from_array(cls, a: np.ndarray | tuple | list) -> Pose:
        return cls(float(a[0]), float(a[1]), float(a[2]))

    def as_array(self) -> np.ndarray:
        return np.array([self.x, self.y, self.theta], dtype=float)

    @property
    def xy(self) -> np.ndarray:
        return np.array([self.x, self.y], dtype=float)

    def compose(self, other: Pose) -> Pose:
        """``self ⊕ other``: ``other`` expressed in this pose's frame, mapped to the world."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        return Pose(
            self.x + c * other.x - s * other.y,
            self.y + s * other.x + c * other.y,
            float(wrap_angle(self.theta + other.theta)),
        )

    __matmul__ = compose

    def inverse(self) -> Pose:
        c, s = math.cos(self.theta), math.sin(self.theta)
        return Pose(-(c * self.x + s * self.y), s * self.x - c * self.y, float(wrap_angle(-self.theta)))

    def between(self, other: Pose) -> Pose:
        """The relative pose ``self⁻¹ ⊕ other``: where ``other`` is, seen from ``self``."""
        return self.inverse().compose(other)

    def transform(self, points: np.ndarray) -> np.ndarray:
        """Map ``(N, 2)`` points from this pose's frame into the world frame."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        p = np.asarray(points, dtype=float)
        return np.column_stack((self.x + c * p[:, 0] - s * p[:, 1], self.y + s * p[:, 0] + c * p[:, 1]))

    def distance_to(self, other: Pose) -> float:
        """Euclidean distance between the two positions (metres)."""
        return math.hypot(self.x - other.x, self.y - other.y)

    def error_to(self, truth: Pose) -> tuple[float, float]:
        """The errors of this pose against ``truth``: distance (metres) and the absolute
        orientation difference of Eq. 6 (radians). The one error rule of every row."""
        return self.distance_to(truth), abs(float(angdiff(self.theta, truth.theta)))

    def is_finite(self) -> bool:
        return math.isfinite(self.x) and math.isfinite(self.y) and math.isfinite(self.theta)
