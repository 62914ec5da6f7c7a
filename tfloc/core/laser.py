"""The laser range finder g(m, f, q) of the paper: beam angles (Eq. 3) and ranges → points (Eq. 4)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _returns_to_points(ranges: np.ndarray, directions: np.ndarray, max_range: float) -> np.ndarray:
    """Eq. 4 for the beams with a return (finite, > 0, < ``max_range``), in beam order."""
    n = 0
    for i in range(ranges.shape[0]):
        r = ranges[i]
        if np.isfinite(r) and r > 0.0 and r < max_range:
            n += 1
    out = np.empty((n, 2))
    _returns_to_points_into(ranges, directions, max_range, out)
    return out


@njit(cache=True, nogil=True)
def _scan_faults(ranges: np.ndarray, max_range: float) -> tuple[int, int]:
    """One pass over a scan for :func:`tfloc.core.problem.check_ranges`: the first beam with a
    negative range (-1: none) and the number of returns (finite, > 0, < ``max_range``: as
    :meth:`LaserSpec.valid`)."""
    first, returns = -1, 0
    for i in range(ranges.shape[0]):
        r = ranges[i]
        if r < 0.0 and first < 0:
            first = i
        if np.isfinite(r) and r > 0.0 and r < max_range:
            returns += 1
    return first, returns


@njit(cache=True, nogil=True)
def _returns_to_points_into(ranges: np.ndarray, directions: np.ndarray, max_range: float,
                            out: np.ndarray) -> int:
    """:func:`_returns_to_points` into the first rows of ``out`` (``len(ranges)`` rows or as
    many as there are returns); returns their number."""
    k = 0
    for i in range(ranges.shape[0]):
        r = ranges[i]
        if np.isfinite(r) and r > 0.0 and r < max_range:
            out[k, 0] = directions[i, 0] * r
            out[k, 1] = directions[i, 1] * r
            k += 1
    return k


@dataclass(frozen=True)
class LaserSpec:
    """A planar laser scanner.

    Attributes:
        max_range: m, the largest range it reports (metres). Ranges ≥ max_range mean no return.
        fov: f, the field of view (radians).
        resolution: q, the angle between neighbouring beams (radians).
        angle_min: the angle of the first beam relative to the robot's heading (radians).

    Eq. 3 numbers the beams from φ₁ = 0 in the scanner's own frame; here that frame is
    rotated so that beam *i* (0-based) points at ``angle_min + i·resolution`` relative to
    the heading, which is how scan files store them (-90°…+90° for an LMS200).
    """

    max_range: float
    fov: float
    resolution: float
    angle_min: float

    @classmethod
    def lms200(cls) -> LaserSpec:
        """SICK LMS200-30106 as in the paper: 10 m, 180°, 1° (181 beams from -90°)."""
        return cls(10.0, math.pi, math.radians(1.0), -math.pi / 2)

    @classmethod
    def from_degrees(cls, max_range: float, fov_deg: float, resolution_deg: float,
                     angle_min_deg: float | None = None) -> LaserSpec:
        """Build a spec from degrees; ``angle_min_deg`` defaults to a field of view centred on the heading."""
        if angle_min_deg is None:
            angle_min_deg = -fov_deg / 2.0
        return cls(float(max_range), math.radians(fov_deg), math.radians(resolution_deg),
                   math.radians(angle_min_deg))

    @property
    def n_beams(self) -> int:
        """n = f/q + 1 (paper, Sec. 3)."""
        return int(round(self.fov / self.resolution)) + 1

    @cached_property
    def angles(self) -> np.ndarray:
        """Eq. 3: beam angles (radians) relative to the robot's heading, shape ``(n_beams,)``."""
        a = self.angle_min + self.resolution * np.arange(self.n_beams)
        a.setflags(write=False)
        return a

    @cached_property
    def directions(self) -> np.ndarray:
        """Unit vectors ``(cos φᵢ, sin φᵢ)`` of the beams, shape ``(n_beams, 2)`` (read-only)."""
        d = np.column_stack((np.cos(self.angles), np.sin(self.angles)))
        d.setflags(write=False)
        return d

    def every(self, k: int) -> LaserSpec:
        """The scanner of every ``k``-th beam from the first (``ranges[::k]`` is its scan): the same
        first angle and range, ``k`` times the resolution."""
        if k == 1:
            return self
        kept = (self.n_beams - 1) // k
        return LaserSpec(self.max_range, self.resolution * k * kept, self.resolution * k, self.angle_min)

    def valid(self, ranges: np.ndarray) -> np.ndarray:
        """Mask of beams with a return: finite, positive and below ``max_range``."""
        r = np.asarray(ranges, dtype=float)
        return np.isfinite(r) & (r > 0.0) & (r < self.max_range)

    def to_points(self, ranges: np.ndarray, keep_invalid: bool = False) -> np.ndarray:
        """Eq. 4: ranges (metres) → points in the sensor frame, shape ``(k, 2)``.

        Beams with no return are dropped unless ``keep_invalid``, in which case they are NaN rows.
        """
        r = np.asarray(ranges, dtype=float)
        if not keep_invalid and r.shape == (self.n_beams,):
            return _returns_to_points(r, self.directions, float(self.max_range))
        ok = self.valid(r)
        if keep_invalid:
            pts = np.full((len(r), 2), np.nan)
            pts[ok] = self.directions[ok] * r[ok, None]
            return pts
        return self.directions[ok] * r[ok, None]
