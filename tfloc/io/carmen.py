"""CARMEN log reader (``.clf``/``.log``, optionally ``.gz``): FLASER/RLASER, ROBOTLASER1, ODOM, PARAM;
and the raw scan files without timestamps (``*.flaser_no_timestamps.txt``, :func:`read_flaser_no_timestamps`).

Strict: a known message with a truncated or garbled line raises
:class:`~tfloc.errors.LogFormatError` naming ``file:line`` and the problem. ``#`` comments and
blank lines are skipped; other message types (NEFF, SYNC, TRUEPOS, RAWLASER*, …) are counted in
:attr:`CarmenLog.skipped` and otherwise ignored. Units as logged: metres, radians, seconds.

Layouts (CARMEN 0.7 logger)::

    FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp
    ROBOTLASER1 type start_angle fov resolution max_range accuracy remission_mode
                n r1..rn m rem1..remm laser_x laser_y laser_theta robot_x robot_y robot_theta
                tv rv forward_safety side_safety turn_axis ipc_timestamp host logger_timestamp
    ODOM x y theta tv rv accel ipc_timestamp host logger_timestamp
    PARAM name value [ipc_timestamp host logger_timestamp]
"""

from __future__ import annotations

import math
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.errors import LogFormatError

from .text import read_text

_MSG = re.compile(r"^[A-Z][A-Z0-9_]*$")


@dataclass(frozen=True, eq=False)
class LaserRecord:
    """One laser scan of the log.

    Attributes:
        kind: message type (``FLASER``, ``RLASER`` or ``ROBOTLASER1``).
        ranges: ``(n,)`` metres, as logged (no-return values such as 81.9 m are kept).
        pose: the laser pose of the line (FLASER ``x y theta``; ROBOTLASER1 laser pose).
        odom: the robot's odometry pose of the line.
        timestamp: ``ipc_timestamp`` (s). logger_timestamp: ``logger_timestamp`` (s).
        host: the ipc host name. line: 1-based line number in the file.
        laser: the scanner as the line states it (ROBOTLASER1's ``start_angle``, ``fov``,
            ``resolution``, ``max_range``: radians, metres); ``None`` for FLASER/RLASER, which
            store no angles.
    """

    kind: str
    ranges: np.ndarray
    pose: Pose
    odom: Pose
    timestamp: float
    logger_timestamp: float
    host: str
    line: int
    laser: LaserSpec | None = None


@dataclass(frozen=True)
class OdomRecord:
    """One ODOM message: pose (m, rad), velocities ``tv`` (m/s), ``rv`` (rad/s), ``accel``."""

    pose: Pose
    tv: float
    rv: float
    accel: float
    timestamp: float
    logger_timestamp: float
    host: str
    line: int


@dataclass(frozen=True, eq=False)
class CarmenLog:
    """The parsed content of a CARMEN log."""

    path: Path
    lasers: tuple[LaserRecord, ...]
    odometry: tuple[OdomRecord, ...] = ()
    params: dict = field(default_factory=dict)
    skipped: dict = field(default_factory=dict)

    def ranges(self) -> np.ndarray:
        """All scans' ranges as one ``(N, n)`` array (metres); all scans must have ``n`` beams."""
        n = {len(r.ranges) for r in self.lasers}
        if len(n) != 1:
            raise LogFormatError(f"{self.path}: scans have different beam counts {sorted(n)}")
        return np.vstack([r.ranges for r in self.lasers])

    def poses(self) -> np.ndarray:
        """The scans' line poses ``(N, 3)`` (m, rad)."""
        return np.array([r.pose.as_array() for r in self.lasers]).reshape(-1, 3)


class _Line:
    """Token cursor over one line that reports problems as ``file:line: ...``."""

    def __init__(self, path: Path, lineno: int, tokens: list[str]) -> None:
        self.path, self.lineno, self.tok, self.i = path, lineno, tokens, 1

    def fail(self, msg: str) -> LogFormatError:
        return LogFormatError(f"{self.path}:{self.lineno}: {self.tok[0]}: {msg}")

    def need(self, k: int, what: str) -> None:
        if self.i + k > len(self.tok):
            raise self.fail(f"line is truncated: {len(self.tok)} fields, {what} missing "
                            f"(needs at least {self.i + k})")

    def num(self, what: str) -> float:
        self.need(1, what)
        s = self.tok[self.i]
        try:
            v = float(s)
        except ValueError:
            raise self.fail(f"{what} is not a number: {s!r} (field {self.i + 1})") from None
        if not math.isfinite(v):
            raise self.fail(f"{what} is not finite: {s!r} (field {self.i + 1})")
        self.i += 1
        return v

    def count(self, what: str) -> int:
        s = self.tok[self.i] if self.i < len(self.tok) else ""
        v = self.num(what)
        if v != int(v) or v < 0:
            raise self.fail(f"{what} is not a non-negative integer: {s!r}")
        return int(v)

    def nums(self, k: int, what: str) -> np.ndarray:
        self.need(k, f"{what} ({k} values)")
        vals = [self.num(f"{what}[{j}]") for j in range(k)]
        return np.array(vals, dtype=float)

    def word(self, what: str) -> str:
        self.need(1, what)
        self.i += 1
        return self.tok[self.i - 1]

    def pose(self, what: str) -> Pose:
        return Pose(self.num(f"{what} x"), self.num(f"{what} y"), self.num(f"{what} theta"))

    def stamps(self) -> tuple[float, str, float]:
        t = self.num("ipc_timestamp")
        host = self.word("hostname")
        lt = self.num("logger_timestamp")
        return t, host, lt

    def end(self) -> None:
        if self.i != len(self.tok):
            raise self.fail(f"{len(self.tok) - self.i} unexpected extra field(s) after field "
                            f"{self.i} (wrong beam count?)")


def _flaser(c: _Line) -> LaserRecord:
    n = c.count("num_readings")
    if n == 0:
        raise c.fail("num_readings is 0")
    want = n + 11  # name, n, n ranges, 2 poses, ipc_timestamp, host, logger_timestamp
    if len(c.tok) != want:
        raise c.fail(f"{len(c.tok)} fields, expected {want} for num_readings={n} "
                     f"({'line is truncated or ' if len(c.tok) < want else ''}wrong beam count)")
    r = c.nums(n, "range")
    if (r < 0).any():
        raise c.fail(f"negative range at beam {int(np.argmax(r < 0))}")
    pose, odom = c.pose("pose"), c.pose("odom")
    t, host, lt = c.stamps()
    c.end()
    return LaserRecord(c.tok[0], r, pose, odom, t, lt, host, c.lineno)


def _robotlaser1(c: _Line) -> LaserRecord:
    c.num("laser_type")
    start, fov, res, maxr = (c.num(w) for w in ("start_angle", "field_of_view",
                                                 "angular_resolution", "maximum_range"))
    c.num("accuracy")
    c.num("remission_mode")
    n = c.count("num_readings")
    r = c.nums(n, "range")
    if (r < 0).any():
        raise c.fail(f"negative range at beam {int(np.argmax(r < 0))}")
    c.nums(c.count("num_remissions"), "remission")
    laser, robot = c.pose("laser pose"), c.pose("robot pose")
    for w in ("tv", "rv", "forward_safety_dist", "side_safety_dist", "turn_axis"):
        c.num(w)
    t, host, lt = c.stamps()
    c.end()
    return LaserRecord("ROBOTLASER1", r, laser, robot, t, lt, host, c.lineno,
                       LaserSpec(maxr, fov, res, start))


def _odom(c: _Line) -> OdomRecord:
    pose = c.pose("odom")
    tv, rv, acc = c.num("tv"), c.num("rv"), c.num("accel")
    t, host, lt = c.stamps()
    c.end()
    return OdomRecord(pose, tv, rv, acc, t, lt, host, c.lineno)


def read_carmen(path: str | Path) -> CarmenLog:
    """Read a CARMEN log (plain or gzip, detected by content). Errors name ``file:line``."""
    path = Path(path)
    lines = read_text(path, LogFormatError, "log file", latin1=True).splitlines()
    lasers: list[LaserRecord] = []
    odom: list[OdomRecord] = []
    params: dict[str, str] = {}
    skipped: Counter[str] = Counter()
    for lineno, text in enumerate(lines, start=1):
        tok = text.split()
        if not tok or tok[0].startswith("#"):
            continue
        kind = tok[0]
        if not _MSG.match(kind):
            raise LogFormatError(f"{path}:{lineno}: not a CARMEN message: starts with {kind[:20]!r}")
        c = _Line(path, lineno, tok)
        if kind in ("FLASER", "RLASER"):
            lasers.append(_flaser(c))
        elif kind == "ROBOTLASER1":
            lasers.append(_robotlaser1(c))
        elif kind == "ODOM":
            odom.append(_odom(c))
        elif kind == "PARAM":
            if len(tok) < 3:
                raise c.fail("line is truncated: needs a name and a value")
            params[tok[1]] = tok[2]
        else:
            skipped[kind] += 1
    if not lasers:
        raise LogFormatError(f"{path}: no laser scans (FLASER/RLASER/ROBOTLASER1) in the log")
    return CarmenLog(path, tuple(lasers), tuple(odom), params, dict(skipped))


@dataclass(frozen=True, eq=False)
class RawScans:
    """Every scan of a log without timestamps (``*.flaser_no_timestamps.txt[.gz]``).

    Attributes:
        path: the file read.
        ranges: ``(N, n)`` metres, as logged (no-return values kept).
        odom: ``(N, 3)`` the robot's raw odometry pose of each scan (m, rad).
        lines: ``(N,)`` 1-based line of each scan in the file, for messages.
    Scan ``k`` is the ``k``-th laser scan of the original log (the file's ``scan_index``).
    """

    path: Path
    ranges: np.ndarray
    odom: np.ndarray
    lines: np.ndarray


def read_flaser_no_timestamps(path: str | Path) -> RawScans:
    """Read ``<scan_index> <n_beams> r_1 … r_n x y theta`` lines (``#`` comments skipped).

    Strict: the indices run 0, 1, 2, … in file order, every scan has the first scan's beam
    count, every value is a finite number and no range is negative; otherwise
    :class:`~tfloc.errors.LogFormatError` naming ``file:line``."""
    path = Path(path)
    text = read_text(path, LogFormatError, "raw scan file", latin1=True)
    ranges: list[np.ndarray] = []
    odom: list[np.ndarray] = []
    lines: list[int] = []
    n_beams = 0
    for lineno, line in enumerate(text.splitlines(), start=1):
        tok = line.split()
        if not tok or tok[0].startswith("#"):
            continue
        where = f"{path}:{lineno}"
        if len(tok) < 2 or not tok[0].isdecimal() or not tok[1].isdecimal():
            raise LogFormatError(f"{where}: expected '<scan_index> <n_beams> ranges… x y theta', "
                                 f"got {line[:40]!r}")
        index, n = int(tok[0]), int(tok[1])
        if index != len(ranges):
            raise LogFormatError(f"{where}: scan index {index}, expected {len(ranges)} (indices run 0, 1, 2, …)")
        if n == 0 or (n_beams and n != n_beams):
            raise LogFormatError(f"{where}: {n} beams, expected {n_beams or 'at least 1'}")
        n_beams = n
        if len(tok) != n + 5:
            raise LogFormatError(f"{where}: {len(tok)} fields, expected {n + 5} for {n} beams "
                                 "(index, beam count, ranges, x y theta)")
        try:
            vals = np.array(tok[2:], dtype=float)
        except ValueError:
            bad = next(k for k, s in enumerate(tok[2:]) if not _is_number(s))
            raise LogFormatError(f"{where}: field {bad + 3} is not a number: {tok[bad + 2][:20]!r}") from None
        if not np.isfinite(vals).all():
            k = int(np.argmin(np.isfinite(vals)))
            raise LogFormatError(f"{where}: field {k + 3} is not finite: {tok[k + 2][:20]!r}")
        if (vals[:n] < 0).any():
            raise LogFormatError(f"{where}: negative range at beam {int(np.argmax(vals[:n] < 0))}")
        ranges.append(vals[:n])
        odom.append(vals[n:])
        lines.append(lineno)
    if not ranges:
        raise LogFormatError(f"{path}: no scans in the file")
    return RawScans(path, np.vstack(ranges), np.vstack(odom), np.array(lines, dtype=np.int64))


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True
