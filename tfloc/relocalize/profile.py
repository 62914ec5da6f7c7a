"""The range profile of a scan: the median range in each of a few sectors of the field of view, a
heading-dependent place signature that survives clutter, glass and dropped returns.

The index stores one profile per virtual scan (a lattice position × heading); a query compares the
real scan's profile, its sectors shifted over the gap between two index headings, with every
entry's (:func:`tfloc.relocalize.profile_kernel.place_distances`). Three choices make it hold on
real scans, where the rotation-invariant distributions of :mod:`tfloc.relocalize.signature` fail:

* a sector's value is the **median** of its returns, so a person or a chair leg in a few beams
  leaves it unchanged;
* a real scan's **no-return beams are unknown** (``no_return="unknown"``), not far: a real scanner
  returns nothing off glass, black surfaces and at grazing angles where the map has a wall a metre
  away; a sector without a return is left out of the comparison. A virtual scan's no-return is
  open space (nothing within the laser's range), so the index counts it as far;
* the per-sector difference is **truncated** (``truncation``, a fraction of ``cap``), so a few
  sectors that see through a door or glass the map drew closed cost a bounded amount.

Ranges are capped at ``cap`` metres and divided by it (values in [0, 1]). Sectors cover the field
of view less ``margin`` at each end, so a shifted sector still lies inside it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tfloc.core.laser import LaserSpec

from .profile_kernel import sector_medians

UNKNOWN, FAR = "unknown", "far"


@dataclass(frozen=True)
class ProfileConfig:
    """The range profile's sectors (metres, radians)."""

    RULES: ClassVar[dict] = {">= 1": ("sectors",), ">= 0": ("margin",), "> 0": ("cap",)}

    sectors: int = 24  #: sectors over the field of view less the margins
    margin: float = float(np.radians(12.0))  #: left out at each end of the field of view (rad): covers the query's shifts
    cap: float = 10.0  #: ranges beyond this count as this (metres)


def _bounds(laser: LaserSpec, cfg: ProfileConfig, shifts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and past-last beam index ``(K·S,)`` of every sector at every shift (radians)."""
    angles = laser.angle_min + np.arange(laser.n_beams) * laser.resolution
    edges = np.linspace(laser.angle_min + cfg.margin, laser.angle_min + laser.fov - cfg.margin,
                        cfg.sectors + 1)
    e = edges[None, :] + np.asarray(shifts, dtype=float)[:, None]
    starts = np.searchsorted(angles, e[:, :-1], side="left").ravel()
    stops = np.searchsorted(angles, e[:, 1:], side="left").ravel()
    return starts.astype(np.int64), stops.astype(np.int64)


def _values(ranges: np.ndarray, laser: LaserSpec, cap: float, no_return: str) -> np.ndarray:
    """Ranges ``(N, B)`` as capped fractions of ``cap``; no-return beams 1 (far) or NaN (unknown)."""
    r = np.atleast_2d(np.asarray(ranges, dtype=float))
    ok = laser.valid(r)
    return np.where(ok, np.minimum(np.where(ok, r, cap), cap) / cap, 1.0 if no_return == FAR else np.nan)


def index_profiles(ranges: np.ndarray, laser: LaserSpec, cfg: ProfileConfig) -> np.ndarray:
    """Profiles ``(N, sectors)`` (float32, fractions of ``cap``) of ``(N, B)`` virtual scans: a
    no-return beam is open space (far), and so is a sector without beams (too many sectors)."""
    starts, stops = _bounds(laser, cfg, np.zeros(1))
    med = sector_medians(_values(ranges, laser, cfg.cap, FAR), starts, stops)
    return np.where(np.isnan(med), np.float32(1.0), med)


def query_profiles(ranges: np.ndarray, laser: LaserSpec, cfg: ProfileConfig, shifts: np.ndarray,
                   no_return: str = UNKNOWN) -> np.ndarray:
    """Profiles ``(K, sectors)`` (float32) of one real scan with its sectors shifted by each of
    ``shifts`` (radians); a sector without a return is NaN (unknown) unless ``no_return="far"``."""
    starts, stops = _bounds(laser, cfg, shifts)
    med = sector_medians(_values(ranges, laser, cfg.cap, no_return), starts, stops)
    return med.reshape(len(shifts), cfg.sectors)


def query_shifts(headings: int, count: int) -> np.ndarray:
    """``count`` shifts (radians) evenly over ± half the gap between two of ``headings`` index
    headings (0 alone for one shift)."""
    half = np.pi / headings
    return np.zeros(1) if count == 1 else np.linspace(-half, half, count)
