"""The rows of the timing measurements: the timing pass's and the scaling study's.

Like :class:`~tfloc.core.result.ResultRow`, each is a frozen dataclass that every producer,
reader and table passes around; text exists only at the edge (:mod:`tfloc.io.table`:
``timing.csv``, ``scaling.csv``, ``prep.csv``, ``skips.csv``, whose columns are these fields in
order). Times per call are in milliseconds, preparation times in seconds, memory in MB; a value
not measured is NaN (an empty cell). A status is a :class:`~tfloc.core.result.Status`; a
preparation row's is ``None`` for a matcher the study did not run at that map (over budget,
written ``skipped``).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..result import Status


@dataclass(frozen=True)
class TimingRow:
    """One ``localize`` of the timing pass: the scan (dataset, id, group), the matcher's label,
    its place in the scan's rotated order (0 = first) and its CPU and wall time (ms)."""

    dataset: str
    scan_id: str
    group: str
    matcher: str
    position: int
    cpu_ms: float
    wall_ms: float


@dataclass(frozen=True)
class ScanRow:
    """One timed ``localize`` of the scaling study. ``size`` is the level's x (m² of map extent,
    beams, or the offset bin's centre in metres); ``tiles`` the map's tile count, ``beams`` and
    ``fov_deg`` the laser's; ``init_dist_m`` the initial distance offset (m); ``position`` the
    matcher's place in the scan's rotated order; CPU, system and wall time (ms; NaN where the
    matcher raised); errors against the truth (m, °); ``success`` 0 or 1."""

    matcher: str
    axis: str
    kind: str
    level: str
    size: float
    tiles: int
    beams: int
    fov_deg: float
    scan_id: str
    offset_bin: str
    init_dist_m: float
    position: int
    cpu_ms: float
    sys_ms: float
    wall_ms: float
    dist_err_m: float
    orient_err_deg: float
    success: int
    status: Status

    @property
    def level_key(self) -> str:
        """``axis/kind/level``: the level's name in ``run.json``."""
        return f"{self.axis}/{self.kind}/{self.level}"


#: a preparation row's matcher for building the map itself (its own arrays)
MAP = "(map)"


@dataclass(frozen=True)
class PrepRow:
    """One map's preparation by one matcher (or :data:`MAP`: building the map): the map's kind,
    tile count, extent (m²), grid cells and vector segments, ``prepare``'s CPU and wall time (s),
    the resident memory it kept and its peak above the memory before (MB; NaN where the OS cannot
    tell). ``status`` ``None``: not run at this map (over budget)."""

    matcher: str
    kind: str
    tiles: int
    size: float
    cells: int
    segments: int
    prep_cpu_s: float
    prep_wall_s: float
    rss_delta_mb: float
    peak_mb: float
    status: Status | None


@dataclass(frozen=True)
class SkipRow:
    """A matcher the study did not run at a level (axis, kind, level, its size) and why (the
    budget it went over, and where)."""

    axis: str
    kind: str
    level: str
    size: float
    matcher: str
    why: str
