"""Native-rate real sequences: every scan of the Intel, MIT CSAIL and ACES logs as the robot
recorded it, with the robot's raw odometry.

``real-<log>-native`` holds every laser scan of the original log in time order, from the first
scan the SLAM-corrected log kept to the end of the log. ``odom_*`` is the raw odometry pose the
log stores with each scan (nothing drawn). ``true_*`` is the corrected pose on the scans the
corrected log kept, each equal to exactly one raw scan (identical ranges, unique and in order:
:func:`match_corrected`), and empty elsewhere: those rows are tracked, not scored. The robot
starts at the first corrected pose, unperturbed, as in :mod:`~tfloc.datasets.real_sequences`;
laser and no-return code as in :mod:`~tfloc.datasets.real`; map: the log's as-built grid
(``maps/real-<log>.yaml``, written by :func:`tfloc.datasets.real.build_all`).

**Stamps.** MIT CSAIL: the clf's own ``ipc_timestamp`` (the clock of its relations, whose path
the dataset's ``scenario.json`` names in ``"relations"``). Intel and ACES: their raw scan files
carry no time, so a scan's stamp is interpolated linearly by scan index between the matched
corrected scans' logger times (:func:`interpolated_stamps`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose, wrap_angle
from tfloc.errors import DatasetError
from tfloc.io.carmen import read_carmen, read_flaser_no_timestamps
from tfloc.io.scenario import SEQUENCE, Scan, write_scenario

from .real import REAL_LOGS, clean_ranges, front_scans
from .real_sequences import TITLES

#: each log's corrected log (under ``data/real``), laser and no-return range (m), by key
CORRECTED = {key: (rel, laser, no_return) for key, rel, laser, no_return in REAL_LOGS}
#: the condition every native sequence carries (its sequence set in reports)
CONDITION = {"name": "real-native", "label": "every raw scan, raw odometry", "odom_noise": "raw",
             "slip": False, "people": False}


@dataclass(frozen=True)
class NativeLog:
    """One log: its key (``intel``, ``csail``, ``aces``), the file of every raw scan (under
    ``data/real``), whether that file is a CARMEN clf with stamps, and its relations file."""

    key: str
    raw: str
    clf: bool = False
    relations: str | None = None


NATIVE_LOGS = (NativeLog("intel", "intel/intel.flaser_no_timestamps.txt.gz"),
               NativeLog("csail", "mit-csail/mit-csail.clf.gz", clf=True,
                         relations="mit-csail/mit-csail.relations"),
               NativeLog("aces", "aces/aces.flaser_no_timestamps.txt.gz"))


@dataclass(frozen=True, eq=False)
class RawLog:
    """Every scan of a log: ``ranges`` ``(N, n)`` metres as logged, ``odom`` ``(N, 3)`` the raw
    odometry (m, rad), ``stamps`` ``(N,)`` seconds or ``None`` (the file has no time)."""

    ranges: np.ndarray
    odom: np.ndarray
    stamps: np.ndarray | None


@dataclass(frozen=True, eq=False)
class Stamps:
    """Interpolated stamps (s) of scans ``0 … N−1``; ``dropped`` knots were left out; ``period_s``
    is the median seconds per scan between the kept knots (used beyond them)."""

    seconds: np.ndarray
    dropped: int
    period_s: float


def read_raw(path: Path, clf: bool, laser: LaserSpec) -> RawLog:
    """The raw scans of a clf (FLASER lines: raw odometry, ``ipc_timestamp``) or of a
    ``*.flaser_no_timestamps`` file (no time), all of ``laser``'s beam count."""
    if clf:
        scans = front_scans(read_carmen(path), laser)
        return RawLog(np.vstack([s.ranges for s in scans]), np.array([s.odom.as_array() for s in scans]),
                      np.array([s.timestamp for s in scans]))
    raw = read_flaser_no_timestamps(path)
    if raw.ranges.shape[1] != laser.n_beams:
        raise DatasetError(f"{path}:{raw.lines[0]}: {raw.ranges.shape[1]} beams, expected {laser.n_beams}")
    return RawLog(raw.ranges, raw.odom, None)


def match_corrected(raw: np.ndarray, corrected: np.ndarray, raw_path: Path, corrected_path: Path,
                    corrected_lines: np.ndarray) -> np.ndarray:
    """The index of the raw scan each corrected scan equals (identical ranges, metres): exactly
    one raw scan each, in order (strictly increasing); else a :class:`DatasetError` naming the
    corrected file and line."""
    where: dict[bytes, list[int]] = {}
    for i, r in enumerate(np.ascontiguousarray(raw, dtype=float)):
        where.setdefault(r.tobytes(), []).append(i)
    out = np.empty(len(corrected), dtype=np.int64)
    for k, r in enumerate(np.ascontiguousarray(corrected, dtype=float)):
        hits = where.get(r.tobytes(), [])
        at = f"{corrected_path}:{corrected_lines[k]}"
        if len(hits) != 1:
            raise DatasetError(f"{at}: the corrected scan's ranges equal {len(hits)} scans of {raw_path} "
                               f"{'(' + ', '.join(map(str, hits[:5])) + ') ' if hits else ''}"
                               "where exactly one is expected")
        if k and hits[0] <= out[k - 1]:
            raise DatasetError(f"{at}: the corrected scan equals raw scan {hits[0]} of {raw_path}, not "
                               f"after raw scan {out[k - 1]} of the corrected scan before it: not in order")
        out[k] = hits[0]
    return out


def interpolated_stamps(at: np.ndarray, times_s: np.ndarray, n: int, where: str) -> Stamps:
    """Stamps (s) of scans ``0 … n−1`` from knots (scan ``at[k]`` recorded at ``times_s[k]``):
    linear in the scan index between knots. A knot whose time is not below every later knot's is
    left out (a corrected log's times step back now and then); before the first and after the
    last kept knot, the median period between kept knots. Stamps not strictly increasing at the
    written µs raise a :class:`DatasetError` naming ``where``."""
    at, t = np.asarray(at, dtype=float), np.asarray(times_s, dtype=float)
    later = np.minimum.accumulate(t[::-1])[::-1]
    keep = np.append(t[:-1] < later[1:], True)
    a, t = at[keep], t[keep]
    if len(a) < 2:
        raise DatasetError(f"{where}: fewer than two increasing corrected scan times to interpolate between")
    period = float(np.median(np.diff(t) / np.diff(a)))
    idx = np.arange(n, dtype=float)
    s = np.interp(idx, a, t)
    s = np.where(idx < a[0], t[0] - (a[0] - idx) * period, s)
    s = np.where(idx > a[-1], t[-1] + (idx - a[-1]) * period, s)
    check_increasing(s, where)
    return Stamps(s, int((~keep).sum()), period)


def check_increasing(stamps_s: np.ndarray, where: str) -> None:
    """Raise a :class:`DatasetError` naming ``where`` unless the stamps (s) increase strictly as
    written (µs)."""
    bad = np.flatnonzero(np.diff(np.round(stamps_s, 6)) <= 0)
    if bad.size:
        raise DatasetError(f"{where}: stamps do not increase after scan {bad[0]} "
                           f"({stamps_s[bad[0]]:.6f} then {stamps_s[bad[0] + 1]:.6f})")


def _path_m(poses: np.ndarray) -> float:
    return float(np.hypot(*np.diff(poses[:, :2], axis=0).T).sum())


def native_scans(real: Path, log: NativeLog) -> tuple[list[Scan], dict]:
    """The rows of ``real-<log>-native`` (module notes; ids ``r<raw index>``) and a summary."""
    rel, laser, no_return = CORRECTED[log.key]
    corrected_path, raw_path = real / rel, real / log.raw
    corr = front_scans(read_carmen(corrected_path), laser)
    raw = read_raw(raw_path, log.clf, laser)
    at = match_corrected(raw.ranges, np.vstack([s.ranges for s in corr]), raw_path, corrected_path,
                         np.array([s.line for s in corr]))
    n_raw = len(raw.ranges)
    if raw.stamps is None:
        made = interpolated_stamps(at, np.array([s.logger_timestamp for s in corr]), n_raw, str(raw_path))
        stamps, dropped, period = made.seconds, made.dropped, made.period_s
    else:
        check_increasing(raw.stamps, str(raw_path))
        stamps, dropped, period = raw.stamps, 0, float(np.median(np.diff(raw.stamps)))
    Q = np.array([s.pose.as_array() for s in corr])
    truth = {int(i): Pose.from_array(q) for i, q in zip(at, Q, strict=True)}
    first = int(at[0])
    rows = [Scan(f"r{i:05d}", "real", clean_ranges(raw.ranges[i], no_return),
                 truth[i] if i == first else None, truth.get(i), stamp=float(stamps[i]),
                 odom=Pose.from_array(raw.odom[i]))
            for i in range(first, n_raw)]
    odom = raw.odom[first:]
    steps = np.hypot(*np.diff(odom[:, :2], axis=0).T)
    turns = np.degrees(np.abs(wrap_angle(np.diff(odom[:, 2]))))
    start = truth[first]
    reckoned = start.compose(Pose.from_array(raw.odom[first]).between(Pose.from_array(raw.odom[at[-1]])))
    gaps = np.diff(at)
    return rows, {
        "raw_scans": n_raw, "first_raw_scan": first, "last_truth_raw_scan": int(at[-1]),
        "scans": len(rows), "truth_scans": len(at),
        "distance_m": round(_path_m(Q), 3), "odometry_distance_m": round(_path_m(odom), 3),
        "median_truth_gap_scans": float(np.median(gaps)), "max_truth_gap_scans": int(gaps.max()),
        "max_odom_step_m": round(float(steps.max()), 3), "max_odom_turn_deg": round(float(turns.max()), 2),
        "dead_reckoning_end_error_m": round(reckoned.distance_to(Pose.from_array(Q[-1])), 3),
        "stamps": ("the clf's ipc_timestamp" if raw.stamps is not None else
                   "interpolated linearly by raw scan index between the matched corrected scans' "
                   "logger times; a corrected time not below a later one is left out; after the "
                   "last matched scan at the median period"),
        "knots_dropped": dropped, "period_s": round(period, 6),
        "duration_s": round(float(stamps[-1] - stamps[first]), 3)}


def _description(log: NativeLog, s: dict) -> str:
    title = TITLES[log.key]
    if log.clf:
        when = "stamp = the clf's ipc_timestamp (the relations' clock)."
    else:
        when = ("stamp = interpolated linearly by raw scan index between the matched corrected scans' "
                "logger times (the raw scan file has no time"
                + (f"; {s['knots_dropped']} of {s['truth_scans']} corrected times that are not below a "
                   "later one are left out" if s["knots_dropped"] else "")
                + (f"; after the last corrected scan at the median period {s['period_s']:.3f} s"
                   if s["last_truth_raw_scan"] < s["raw_scans"] - 1 else "") + ").")
    return (f"Tracking on the {title} log at its native rate, every raw scan, raw odometry: all "
            f"{s['scans']} laser scans in time order from the first scan the corrected log kept (raw "
            f"scan {s['first_raw_scan']} of {s['raw_scans']}) to the end of the log. odom_* = the "
            "robot's raw odometry of each scan, as logged (dead reckoning from the start ends "
            f"{s['dead_reckoning_end_error_m']:.1f} m from the last corrected pose). true = the corrected "
            f"pose (pseudo ground truth) on the {s['truth_scans']} scans the corrected log kept "
            f"(identical ranges; median {s['median_truth_gap_scans']:g}, max {s['max_truth_gap_scans']} "
            f"raw scans apart; {s['distance_m']:.0f} m), empty elsewhere (tracked, not scored). "
            f"start = the first corrected pose (not perturbed, as in real-{log.key}-sequence); laser "
            f"and no-return code as in real-{log.key}-scan-to-map; map = its grid. " + when)


def build_native(real: Path, out: Path) -> list[Path]:
    """(Re)build ``out/scenarios/real-<log>-native`` on the maps ``out/maps/real-<log>.yaml``."""
    real, out = Path(real), Path(out)
    made = []
    for log in NATIVE_LOGS:
        rows, summary = native_scans(real, log)
        rel, laser, _ = CORRECTED[log.key]
        name = f"real-{log.key}-native"
        root = out / "scenarios" / name
        files = [log.raw, rel] + ([log.relations] if log.relations else [])
        extra = {}
        if log.relations:
            root.mkdir(parents=True, exist_ok=True)
            extra["relations"] = Path(os.path.relpath((real / log.relations).resolve(), root.resolve())).as_posix()
        made.append(write_scenario(
            root, name, out / "maps" / f"real-{log.key}.yaml", laser, rows,
            description=_description(log, summary), mode=SEQUENCE, condition=dict(CONDITION), **extra,
            generator={"command": "tfloc real-data", **summary},
            source={"files": [f"data/real/{f}" for f in files], "provenance": "data/real/*/PROVENANCE.md"}))
        if log.key == NO_TRUTH:
            made.append(_without_truth(root, name, out, laser, rows, summary, files))
    return made


#: the log also bundled with its truth removed: a user's recording as a robot owner has it
NO_TRUTH = "csail"


def _without_truth(root: Path, name: str, out: Path, laser: LaserSpec, rows: list[Scan], summary: dict,
                   files: list[str]) -> Path:
    """``real-<log>-native-no-truth``: the same scans, stamps and odometry with every true pose
    removed (``"truth": false``), the start (first row's ``init_*``) kept as the pose a user would
    give (``import-bag --initial-pose``). What the truth-free verdict is shown on end to end."""
    blind = [replace(r, true=None) for r in rows]
    target = root.parent / f"{name}-no-truth"
    return write_scenario(
        target, target.name, out / "maps" / f"real-{NO_TRUTH}.yaml", laser, blind,
        description=(f"{name} with its truth removed: the same {len(blind)} scans, stamps and raw odometry, "
                     "no true pose (a robot owner's recording: the truth-free verdict ranks its trackers). "
                     f"start = the first corrected pose, as a user would give it. Truth: {name}."),
        mode=SEQUENCE, condition={**CONDITION, "name": "real-native-no-truth", "label": "every raw scan, raw odometry, no truth"}, truth=False,
        generator={"command": "tfloc real-data", "from": name, "scans": len(blind)},
        source={"files": [f"data/real/{f}" for f in files], "provenance": "data/real/*/PROVENANCE.md"})
