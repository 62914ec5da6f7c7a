"""Faults of a recording, found from the recording alone (stamps, odometry increments and
ranges; no truth, no estimates), and stretches of a trajectory the map does not cover.

Each rule's threshold is relative to the recording's own statistics, with a stated floor
(:class:`RecordingRules`; ``docs/data.md`` lists them with what they flag on the bundled data):

* ``scan-gap``: a stamp step longer than ``gap_factor`` × the median period.
* ``scan-empty``: scans without a return; ``scan-sparse``: scans with fewer returns than
  ``sparse_share`` × the recording's median count.
* ``odometry-missing``: scans without an odometry pose, in a recording that has odometry.
* ``odometry-stall``: ``stall_steps`` or more consecutive increments below ``still_m`` and
  ``still_rad`` (the odometry reports no motion) while the scans change: the median |Δr| between
  the stretch's first and last scans (over the beams with a return in both) exceeds
  ``max(change_factor × noise, change_floor_m)``, noise being the 1st percentile of the non-zero
  changes between consecutive scans over the recording (a standing robot's scans differ by the
  sensor's noise; a recording that never stands still gives a larger, more cautious value).
  First to last, not step by step: a moving robot's change adds up, a standing one's flicker
  (noise, a passer-by) does not.
* ``odometry-jump``: an increment (per median period: one over a longer step counts pro rata)
  beyond ``jump_factor`` × the recording's 99th percentile (translation or rotation, at least
  ``jump_floor_m`` / ``jump_floor_rad``), or implying more than ``max_speed`` / ``max_turn``
  (physical limits), or, right after a stall, beyond the 99th percentile (the stalled motion
  caught up in one step).

:func:`coverage_flags` flags, for any trajectory (dead reckoning, a tracker's answers):
``outside-map`` (poses outside the map's known area, :func:`tfloc.maps.known.in_known_area`) and
``unmapped-view`` (``unmapped_scans`` or more scans in a row of which fewer than
``unmapped_share`` of the returns lie within ``near_m`` of the map).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose, wrap_angle
from tfloc.core.scan import Scan
from tfloc.maps.fields import distance_field
from tfloc.maps.known import in_known_area

KINDS = ("scan-gap", "scan-empty", "scan-sparse", "odometry-missing", "odometry-stall", "odometry-jump",
         "outside-map", "unmapped-view")


@dataclass(frozen=True)
class RecordingRules:
    """The thresholds of the recording checks (metres, radians, seconds; factors of the
    recording's own statistics)."""

    gap_factor: float = 5.0  #: a stamp step beyond this × the median period is a scan gap
    sparse_share: float = 0.1  #: fewer returns than this × the median count: a sparse scan
    still_m: float = 1e-4  #: an odometry increment below this (m) ...
    still_rad: float = 1e-4  #: ... and this (rad) reports no motion
    stall_steps: int = 2  #: this many still increments in a row while the scans change: a stall
    change_factor: float = 3.0  #: the scans change: median |Δr| beyond this × the noise ...
    change_floor_m: float = 0.1  #: ... and beyond this (m)
    jump_factor: float = 3.0  #: an increment beyond this × the 99th percentile is a jump ...
    jump_floor_m: float = 0.1  #: ... if it is also beyond this (m) ...
    jump_floor_rad: float = 0.1  #: ... or this (rad)
    max_speed: float = 3.0  #: m/s: faster is a jump whatever the recording (indoor robots ≤ 2 m/s)
    max_turn: float = 2 * math.pi  #: rad/s: a faster turn is a jump whatever the recording
    near_m: float = 0.3  #: a return this close (m) to the map's geometry is one the map explains
    unmapped_share: float = 0.2  #: fewer explained returns than this share: the map misses the view
    unmapped_scans: int = 3  #: ... over at least this many scans in a row


@dataclass(frozen=True)
class Flag:
    """One flagged stretch: ``kind`` (:data:`KINDS`), its first and last scan (index into the
    recording and scan_id), the time it spans (s, first to last stamp; NaN without stamps) and
    a one-line message."""

    kind: str
    first: int
    last: int
    first_id: str
    last_id: str
    duration_s: float
    message: str

    @property
    def scans(self) -> int:
        return self.last - self.first + 1

    def line(self) -> str:
        """``kind  first…last  (n scans, s)  message``: the verb's line."""
        where = self.first_id if self.first == self.last else f"{self.first_id}…{self.last_id}"
        dur = "" if math.isnan(self.duration_s) else f", {self.duration_s:.2f} s"
        return f"{self.kind:<16} {where:<15} ({self.scans} scans{dur}): {self.message}"

    def record(self) -> dict:
        return {"kind": self.kind, "first": self.first_id, "last": self.last_id, "scans": self.scans,
                "duration_s": None if math.isnan(self.duration_s) else round(self.duration_s, 3),
                "message": self.message}


@dataclass(frozen=True)
class RecordingCheck:
    """What :func:`check_recording` found: the flags in order of their first scan, and the
    recording's size (scans, seconds) and median period (s; NaN without stamps)."""

    flags: tuple[Flag, ...]
    scans: int
    duration_s: float
    period_s: float
    rules: RecordingRules = field(default_factory=RecordingRules)

    def counts(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for f in self.flags:
            out[f.kind] = out.get(f.kind, 0) + 1
        return out

    def summary(self) -> str:
        """One line: the recording's size and the flags by kind."""
        span = "" if math.isnan(self.duration_s) else f" over {self.duration_s:.1f} s"
        rate = "" if math.isnan(self.period_s) else f" (period {self.period_s:.3f} s)"
        found = ", ".join(f"{n} {k}" for k, n in self.counts().items()) or "no flags"
        return f"{self.scans} scans{span}{rate}: {found}"

    def lines(self, limit: int | None = None, more: str = "") -> list[str]:
        """The flags one per line (:meth:`Flag.line`), at most ``limit`` of them and then how
        many more there are (and ``more``: where to see them all)."""
        shown = self.flags if limit is None else self.flags[:limit]
        out = [f.line() for f in shown]
        if len(shown) < len(self.flags):
            out.append(f"… {len(self.flags) - len(shown)} more" + (f": {more}" if more else ""))
        return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """The maximal runs of True in ``mask``: ``(start, end)`` inclusive."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True))


class _Flags:
    """Builds flags over a recording's scans (ids and stamps)."""

    def __init__(self, ids: Sequence[str], stamps: np.ndarray | None) -> None:
        self.ids, self.t, self.out = list(ids), stamps, []

    def add(self, kind: str, first: int, last: int, message: str) -> None:
        dur = math.nan if self.t is None else float(self.t[last] - self.t[first])
        self.out.append(Flag(kind, int(first), int(last), self.ids[first], self.ids[last], dur, message))

    def done(self) -> tuple[Flag, ...]:
        return tuple(sorted(self.out, key=lambda f: (f.first, KINDS.index(f.kind))))


def scan_change(a: np.ndarray, b: np.ndarray, laser: LaserSpec) -> np.ndarray:
    """Median |Δr| (metres) between scans ``a`` and ``b`` (``(N, n)`` each, row by row) over
    the beams with a return in both; NaN where no beam has one in both."""
    a, b = np.atleast_2d(np.asarray(a, dtype=float)), np.atleast_2d(np.asarray(b, dtype=float))
    both = laser.valid(a) & laser.valid(b)
    d = np.where(both, np.abs(np.where(both, a, 0.0) - np.where(both, b, 0.0)), np.nan)
    out = np.full(len(d), np.nan)
    has = both.any(axis=1)
    out[has] = np.nanmedian(d[has], axis=1)
    return out


def check_recording(scans: Sequence[Scan], laser: LaserSpec,
                    rules: RecordingRules = RecordingRules()) -> RecordingCheck:
    """The recording checks (module notes) on ``scans`` in time order; odometry rules only if
    some scan has odometry, stamp rules only if every scan has a stamp."""
    n = len(scans)
    stamps = np.array([s.stamp for s in scans], dtype=float) if n and all(s.stamp is not None for s in scans) \
        else None
    flags = _Flags([s.scan_id for s in scans], stamps)
    period, dt = math.nan, None
    if stamps is not None and n >= 2:
        dt = np.diff(stamps)
        period = float(np.median(dt[dt > 0])) if (dt > 0).any() else math.nan
        for k in np.flatnonzero(dt > rules.gap_factor * period) + 1:
            flags.add("scan-gap", k - 1, k, f"no scan for {dt[k - 1]:.2f} s ({dt[k - 1] / period:.1f} × the "
                                            f"median period {period:.3f} s)")
    R = np.array([s.ranges for s in scans], dtype=float).reshape(n, laser.n_beams)
    returns = laser.valid(R).sum(axis=1)
    for a, b in _runs(returns == 0):
        flags.add("scan-empty", a, b, "no return in the scan" if a == b else "no return in these scans")
    med = float(np.median(returns)) if n else 0.0
    for a, b in _runs((returns > 0) & (returns < rules.sparse_share * med)):
        flags.add("scan-sparse", a, b, f"{int(returns[a:b + 1].min())} returns at least (the recording's "
                                      f"median: {med:.0f})")
    has_odom = np.array([s.odom is not None for s in scans], dtype=bool)
    if has_odom.any():
        for a, b in _runs(~has_odom):
            flags.add("odometry-missing", a, b, "no odometry pose")
        _odometry(scans, laser, R, has_odom, dt, period, rules, flags)
    dur = math.nan if stamps is None or n == 0 else float(stamps[-1] - stamps[0])
    return RecordingCheck(flags.done(), n, dur, period, rules)


def _odometry(scans: Sequence[Scan], laser: LaserSpec, R: np.ndarray, has_odom: np.ndarray,
              dt: np.ndarray | None, period: float, rules: RecordingRules, flags: _Flags) -> None:
    """The stall and jump rules over the increments between consecutive scans with odometry."""
    odo = np.array([s.odom.as_array() if s.odom is not None else (np.nan,) * 3 for s in scans])
    both = has_odom[1:] & has_odom[:-1]
    dd = np.hypot(*(odo[1:, :2] - odo[:-1, :2]).T)
    da = np.abs(wrap_angle(odo[1:, 2] - odo[:-1, 2]))
    scale = np.ones(len(dd)) if dt is None or math.isnan(period) else period / np.maximum(dt, period)
    dd_n, da_n = dd * scale, da * scale
    if not both.any():
        return
    p99_m, p99_rad = np.percentile(dd_n[both], 99), np.percentile(da_n[both], 99)
    change = scan_change(R[:-1], R[1:], laser)
    moved = change[change > 0]
    noise = float(np.percentile(moved, 1)) if moved.size else 0.0
    tau = max(rules.change_factor * noise, rules.change_floor_m)
    with np.errstate(invalid="ignore"):
        still = both & (dd < rules.still_m) & (da < rules.still_rad)
    after_stall = np.zeros(len(dd), dtype=bool)
    for a, b in _runs(still):
        end = float(scan_change(R[a], R[b + 1], laser)[0])
        if b - a + 1 < rules.stall_steps or not end > tau:
            continue
        flags.add("odometry-stall", a, b + 1, f"odometry unchanged over {b - a + 1} steps while the scans "
                                              f"change by {end:.2f} m first to last (median beam; beyond "
                                              f"{tau:.2f} m)")
        if b + 1 < len(dd):
            after_stall[b + 1] = True
    lim_m = max(rules.jump_factor * p99_m, rules.jump_floor_m)
    lim_rad = max(rules.jump_factor * p99_rad, rules.jump_floor_rad)
    timed = dt is not None and not math.isnan(period)
    per = period if timed else 1.0
    with np.errstate(invalid="ignore"):
        big = (dd_n > lim_m) | (da_n > lim_rad)
        fast = ((dd_n / per > rules.max_speed) | (da_n / per > rules.max_turn)) & timed
        catch = after_stall & ((dd_n > p99_m) | (da_n > p99_rad))
        jump = both & (big | fast | catch)
    for a, b in _runs(jump):
        k = a + int(np.argmax(np.maximum(dd_n[a:b + 1] / max(lim_m, 1e-12), da_n[a:b + 1] / max(lim_rad, 1e-12))))
        why = ("the stalled motion caught up in one step" if catch[k] and not (big[k] or fast[k]) else
               f"beyond {rules.jump_factor:g} × the 99th percentile ({p99_m:.2f} m, {math.degrees(p99_rad):.1f}°)"
               if big[k] else f"{dd_n[k] / per:.1f} m/s and {da_n[k] / per:.1f} rad/s: beyond "
                              f"{rules.max_speed:g} m/s or {rules.max_turn:.2f} rad/s")
        if catch[k] and (big[k] or fast[k]):
            why += ", after a stall"
        flags.add("odometry-jump", a, b + 1, f"odometry moved {dd[k]:.2f} m and {math.degrees(da[k]):.1f}° in one "
                                             f"step ({scans[k + 1].scan_id}): {why}")


def coverage_flags(map_, laser: LaserSpec, scans: Sequence[Scan], poses,
                   rules: RecordingRules = RecordingRules()) -> tuple[Flag, ...]:
    """Stretches where ``poses`` (one per scan: :class:`Pose`, ``None`` or a NaN row of an
    ``(N, 3)`` array, metres and radians, of the laser in the map frame) lie outside the map's
    known area, or where the map explains almost none of the scan's returns (module notes)."""
    P = np.array([(np.nan,) * 3 if p is None else (p.as_array() if isinstance(p, Pose) else p)
                  for p in poses], dtype=float).reshape(-1, 3)
    if len(P) != len(scans):
        raise ValueError(f"{len(P)} poses for {len(scans)} scans")
    stamps = np.array([s.stamp for s in scans], dtype=float) if all(s.stamp is not None for s in scans) else None
    flags = _Flags([s.scan_id for s in scans], stamps)
    given = np.isfinite(P).all(axis=1)
    known = np.zeros(len(P), dtype=bool)
    known[given] = in_known_area(map_, P[given, :2])
    for a, b in _runs(given & ~known):
        flags.add("outside-map", a, b, f"the pose lies outside the map's known area (first at "
                                       f"{P[a, 0]:.2f}, {P[a, 1]:.2f} m)")
    share = explained_share(map_, laser, scans, P, rules.near_m)
    low = known & (share < rules.unmapped_share)
    for a, b in _runs(low):
        if b - a + 1 >= rules.unmapped_scans:
            flags.add("unmapped-view", a, b, f"at most {100 * np.nanmax(share[a:b + 1]):.0f} % of each scan's "
                                             f"returns lie within {rules.near_m:g} m of the map")
    return flags.done()


def explained_share(map_, laser: LaserSpec, scans: Sequence[Scan], poses: np.ndarray,
                    near_m: float) -> np.ndarray:
    """Per scan, the share of its returns that lie within ``near_m`` (m) of the map's geometry
    when the laser is at ``poses`` ``(N, 3)``; NaN without a pose or a return."""
    field = distance_field(map_, 0.05, 2 * near_m, pad=2 * near_m)
    R = np.array([s.ranges for s in scans], dtype=float).reshape(len(scans), laser.n_beams)
    ok = laser.valid(R) & np.isfinite(poses).all(axis=1)[:, None]
    a = poses[:, 2:3] + laser.angles[None, :]
    r = np.where(ok, R, 0.0)
    xy = np.stack([poses[:, 0:1] + r * np.cos(a), poses[:, 1:2] + r * np.sin(a)], axis=-1)
    xy = np.nan_to_num(xy)
    near = field(xy) <= near_m
    n = ok.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, (near & ok).sum(axis=1) / n, np.nan)
