"""The rows of the scaling study's derived tables: ``levels.csv`` (per axis, map kind, matcher
and level) and ``slopes.csv`` (per axis, map kind and matcher: how its CPU grows)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class LevelRow:
    """One matcher at one level: the level's size (m², beams or m), scans, median and 90th
    percentile CPU and median wall time (ms), the success share (fraction) and the share of the
    CPU spent in the kernel (system time)."""

    axis: str
    kind: str
    matcher: str
    level: str
    size: float
    n: int
    cpu_ms_median: float
    cpu_ms_p90: float
    wall_ms_median: float
    success: float
    sys_share: float


@dataclass(frozen=True)
class SlopeRow:
    """How one matcher's median CPU grows along an axis: the log-log slope over ``levels``, ms per
    unit of size, the first and last levels' CPU (ms) and sizes, and whether it ``grows`` (None:
    one level only)."""

    axis: str
    kind: str
    matcher: str
    slope: float
    levels: int
    ms_per_unit: float
    first_ms: float
    last_ms: float
    first_size: float
    last_size: float
    grows: bool | None
