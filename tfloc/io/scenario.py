"""Scenario datasets: ``scenario.json`` + ``scans.csv`` (format in DESIGN.md), strict I/O.

``scans.csv`` columns: ``scan_id,group,true_x,true_y,true_theta,init_x,init_y,init_theta,ranges``
(metres, radians). ``true_*`` may be empty (truth unknown). ``ranges`` holds space-separated
floats; ``inf``, ``nan`` or values ≥ max_range mean no return. Optional columns: ``stamp``
(the scan's time in seconds, e.g. from a ROS bag; may be empty), ``ref_ranges`` and
``odom_x, odom_y, odom_theta`` (the robot's raw odometry pose, odometry frame).

The dataset's **mode** (``scenario.json`` ``"mode"``, :data:`MODES`) says what kind of task its
scans pose:

* ``single`` (default): every row is one problem with its own initial guess (``init_*``);
* ``scan-to-scan``: the same, the map being each row's reference scan (``ref_ranges``; older
  datasets say ``"scan_to_scan": true``);
* ``sequence``: the rows are one trajectory in time order: ``stamp`` strictly increasing,
  ``odom_*`` on every row, ``init_*`` on the first row only (where the robot starts);
* ``global``: no row has an initial guess: each pose is searched over the whole map.

``scenario.json`` ``"truth": false`` declares a dataset without truth (every ``true_*`` empty,
e.g. a user's recording imported without reference poses): :attr:`Scenario.has_truth`, read from
the rows where it is not declared. :func:`check_usable` holds the rules for a sequence that cannot
be tracked at all.
"""

from __future__ import annotations

import csv
import json
import math
import os
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.modes import MODES as ALL_MODES
from tfloc.core.pose import Pose
from tfloc.core.problem import check_ranges
from tfloc.core.scan import Scan
from tfloc.errors import DatasetError

from .text import csv_rows, parse_text

MAX_BEAMS = 1_000_000  # a laser with more beams is a damaged scenario.json, not a scanner
COLUMNS = ["scan_id", "group", "true_x", "true_y", "true_theta", "init_x", "init_y", "init_theta",
           "ranges"]
ODOM_COLUMNS = ["odom_x", "odom_y", "odom_theta"]
SINGLE, SCAN_TO_SCAN, SEQUENCE, GLOBAL = (m.key for m in ALL_MODES.values())
MODES = tuple(ALL_MODES)


@dataclass(frozen=True, eq=False)
class Scenario:
    """A scenario dataset directory's metadata (``scenario.json``)."""

    name: str
    map_path: Path
    laser: LaserSpec
    description: str = ""
    root: Path = field(default_factory=Path)
    extra: dict = field(default_factory=dict)

    @property
    def scans_path(self) -> Path:
        return self.root / "scans.csv"

    @property
    def mode(self) -> str:
        """What kind of task the scans pose (:data:`MODES`; see the module notes)."""
        if self.extra.get("scan_to_scan"):
            return SCAN_TO_SCAN
        return str(self.extra.get("mode", SINGLE))

    @cached_property
    def has_truth(self) -> bool:
        """Whether any row holds a true pose: ``scenario.json``'s ``"truth"`` where declared,
        else read from ``scans.csv`` (its ``true_x`` column only)."""
        if "truth" in self.extra:
            return bool(self.extra["truth"])
        if not self.scans_path.is_file():
            return False
        _, rows = csv_rows(self.scans_path, DatasetError, "scans.csv file", COLUMNS)
        return any((row.get("true_x") or "").strip() for _, row in rows)

    @property
    def paper_scenarios(self) -> tuple[str, ...]:
        """The paper scenarios the dataset declares it poses (:func:`paper_scenarios_of`)."""
        return paper_scenarios_of(self.extra, str(self.root / "scenario.json"))


PAPER_SCENARIOS = ("I", "II", "III")


def paper_scenarios_of(extra: dict, where: str = "scenario.json") -> tuple[str, ...]:
    """The paper scenarios (Section 5) a dataset declares it poses (``"paper_scenarios"``):
    ``I`` (its scans are one sample of Scenario I), ``II`` (binned by initial angle offset),
    ``III`` (binned by initial distance offset); ``()`` for every other dataset."""
    got = extra.get("paper_scenarios", [])
    if not isinstance(got, list) or not set(got) <= set(PAPER_SCENARIOS):
        raise DatasetError(f"{where}: field 'paper_scenarios' must be a list of {', '.join(PAPER_SCENARIOS)}, "
                           f"got {got!r:.60}")
    return tuple(got)


def missing_dataset(root: Path) -> str:
    """One line for a dataset directory that is not one: no such directory (with the closest
    names beside it), or a directory without ``scenario.json``."""
    import difflib

    if root.is_dir():
        return f"{root}: not a scenario dataset (no scenario.json)"
    parent = root.parent if str(root.parent) else Path(".")
    try:
        names = [p.name for p in parent.iterdir() if (p / "scenario.json").is_file()] if parent.is_dir() else []
    except OSError:
        names = []
    close = difflib.get_close_matches(root.name, names, n=3, cutoff=0.6)
    hint = f"; did you mean {' or '.join(str(parent / c) for c in close)}?" if close else ""
    return f"{root}: no such directory{hint}"


def read_scenario(root: str | Path) -> Scenario:
    """Read and validate ``root/scenario.json``."""
    root = Path(root)
    path = root / "scenario.json"
    if not path.is_file():
        raise DatasetError(missing_dataset(root))
    doc = parse_text(path, DatasetError, "scenario.json", json.loads, json.JSONDecodeError, "JSON")
    if not isinstance(doc, dict):
        raise DatasetError(f"{path}: expected a JSON object of scenario fields")
    for key in ("name", "map", "laser"):
        if key not in doc:
            raise DatasetError(f"{path}: missing field {key!r}")
    if not isinstance(doc["map"], str) or not doc["map"].strip():
        raise DatasetError(f"{path}: field 'map' must be a path (a string), got {doc['map']!r:.60}")
    las = doc["laser"]
    try:
        laser = LaserSpec.from_degrees(float(las["max_range"]), float(las["fov_deg"]),
                                       float(las["resolution_deg"]),
                                       None if las.get("angle_min_deg") is None else float(las["angle_min_deg"]))
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise DatasetError(f"{path}: bad 'laser' field ({exc!r:.100}); needs max_range, fov_deg, "
                           "resolution_deg[, angle_min_deg]") from None
    if not all(math.isfinite(v) for v in (laser.max_range, laser.fov, laser.resolution, laser.angle_min)):
        raise DatasetError(f"{path}: laser values must be finite numbers")
    if not (laser.max_range > 0 and 0 < laser.resolution <= laser.fov <= 2 * math.pi + 1e-9):
        raise DatasetError(f"{path}: laser max_range must be positive and 0 < resolution_deg ≤ fov_deg ≤ 360")
    if laser.fov / laser.resolution > MAX_BEAMS:
        raise DatasetError(f"{path}: laser resolution_deg is too fine: more than {MAX_BEAMS} beams")
    extra = {k: v for k, v in doc.items() if k not in ("name", "map", "laser", "description")}
    paper_scenarios_of(extra, str(path))
    if not isinstance(extra.get("truth", False), bool):
        raise DatasetError(f"{path}: field 'truth' must be true or false, got {extra['truth']!r:.40}")
    if extra.get("mode", SINGLE) not in MODES:
        raise DatasetError(f"{path}: field 'mode' must be one of {', '.join(MODES)}, got {extra['mode']!r:.40}")
    try:
        map_path = (root / doc["map"]).resolve()
    except (OSError, ValueError) as exc:
        raise DatasetError(f"{path}: field 'map' is not a usable path ({exc})") from None
    return Scenario(str(doc["name"]), map_path, laser, str(doc.get("description", "")), root, extra)


def _float(text: str, path: Path, line: int, column: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise DatasetError(f"{path}:{line}: column {column!r} is not a number: {text!r}") from None


def _pose(row: dict, prefix: str, path: Path, line: int, optional: bool) -> Pose | None:
    vals = [row.get(f"{prefix}_{k}", "") or "" for k in ("x", "y", "theta")]
    if optional and all(v.strip() == "" for v in vals):
        return None
    p = Pose(*(_float(v, path, line, f"{prefix}_{k}") for v, k in zip(vals, ("x", "y", "theta"), strict=True)))
    if not p.is_finite():
        raise DatasetError(f"{path}:{line}: {prefix} pose is not finite: {p}")
    return p


def parse_ranges(text: str, laser: LaserSpec, path: Path, line: int) -> np.ndarray:
    """Parse the ``ranges`` field: space-separated numbers, then the one range rule
    (:func:`tfloc.core.problem.check_ranges`); errors name ``path:line``."""
    parts = text.split()
    try:
        r = np.array(parts, dtype=float)
    except ValueError:
        bad = next(p for p in parts if not _is_float(p))
        raise DatasetError(f"{path}:{line}: range {bad!r} is not a number") from None
    return check_ranges(r, laser, f"{path}:{line}", DatasetError)


def _is_float(s: str) -> bool:
    try:
        float(s)
        return True
    except ValueError:
        return False


def iter_scans(scenario: Scenario) -> Iterator[Scan]:
    """Yield the scans of ``scans.csv`` one by one, validating each row and the dataset's mode
    (a sequence's order, odometry and starting pose; a global dataset's missing guesses);
    errors name file:line."""
    path = scenario.scans_path
    if not path.is_file():
        raise DatasetError(f"{scenario.root}: missing scans.csv")
    mode = scenario.mode
    header, rows = csv_rows(path, DatasetError, "scans.csv file", COLUMNS)
    if mode == SEQUENCE:
        missing = [c for c in ("stamp", *ODOM_COLUMNS) if c not in header]
        if missing:
            raise DatasetError(f"{path}: a sequence needs the column(s) {', '.join(missing)}")
    seen: set[str] = set()
    last_stamp: float | None = None
    no_truth = scenario.extra.get("truth") is False
    for n, (line, row) in enumerate(rows):
        if None in row or any(row[c] is None for c in COLUMNS):
            raise DatasetError(f"{path}:{line}: wrong number of fields (expected {len(COLUMNS)})")
        sid = row["scan_id"].strip()
        if not sid:
            raise DatasetError(f"{path}:{line}: empty scan_id")
        if sid in seen:
            raise DatasetError(f"{path}:{line}: duplicate scan_id {sid!r}")
        seen.add(sid)
        ref = row.get("ref_ranges")
        stamp_text = (row.get("stamp") or "").strip()
        stamp = _stamp(stamp_text, path, line) if stamp_text else None
        initial = _pose(row, "init", path, line, optional=mode in (SEQUENCE, GLOBAL))
        odom = _pose(row, "odom", path, line, optional=True) if "odom_x" in row else None
        if mode == SEQUENCE:
            if n == 0 and initial is None:
                raise DatasetError(f"{path}:{line}: a sequence's first row needs init_x/y/theta (where the robot starts)")
            if stamp is None:
                raise DatasetError(f"{path}:{line}: a sequence needs a stamp on every row")
            if last_stamp is not None and not stamp > last_stamp:
                raise DatasetError(f"{path}:{line}: stamp {stamp_text} is not after the previous row's "
                                   f"({last_stamp:.6f}): a sequence's rows are in time order")
            if odom is None:
                raise DatasetError(f"{path}:{line}: a sequence needs odom_x/y/theta on every row")
            last_stamp = stamp
        elif mode == GLOBAL and initial is not None:
            raise DatasetError(f"{path}:{line}: a global dataset has no initial pose (init_* must be empty)")
        true = _pose(row, "true", path, line, optional=True)
        if no_truth and true is not None:
            raise DatasetError(f"{path}:{line}: a true pose in a dataset whose scenario.json says "
                               "\"truth\": false")
        yield Scan(sid, row["group"].strip(),
                   parse_ranges(row["ranges"], scenario.laser, path, line),
                   initial, true, line,
                   parse_ranges(ref, scenario.laser, path, line) if ref else None,
                   stamp, odom)
    if mode == SEQUENCE and not seen:
        raise DatasetError(f"{path}: a sequence with no scans")


def _stamp(text: str, path: Path, line: int) -> float:
    t = _float(text, path, line, "stamp")
    if not math.isfinite(t):
        raise DatasetError(f"{path}:{line}: stamp is not finite: {text!r}")
    return t


def check_usable(scenario: Scenario, scans: Sequence[Scan], the_map=None) -> None:
    """Raise a one-line :class:`DatasetError` where a sequence dataset cannot be tracked at all
    (:func:`usable_sequence`'s rules); other modes pass."""
    if scenario.mode == SEQUENCE:
        usable_sequence(scans, the_map, str(scenario.scans_path))


def usable_sequence(scans: Sequence[Scan], the_map=None, where: str = "scans.csv",
                    error: type[Exception] = DatasetError) -> None:
    """The rules for a sequence that cannot be tracked at all, one line naming ``where`` (the
    file, and the row): fewer than 2 scans, or (given ``the_map``) a start pose outside the
    map's known area (:func:`tfloc.maps.known.in_known_area`). Rows without odometry or a start
    pose are refused by :func:`iter_scans`, a scan without a return by the one range rule
    (:func:`tfloc.core.problem.check_ranges`); a recording that is usable but flawed is flagged,
    not refused (:mod:`tfloc.evaluation.recording`)."""
    if len(scans) < 2:
        raise error(f"{where}: a sequence needs at least 2 scans to track, found {len(scans)}")
    start = scans[0].initial
    if the_map is not None and start is not None:
        from tfloc.maps.known import in_known_area

        if not in_known_area(the_map, np.array([[start.x, start.y]]))[0]:
            row = f":{scans[0].line}" if scans[0].line else ""
            b = ", ".join(f"{v:.2f}" for v in the_map.bounds)
            raise error(f"{where}{row}: the start pose of {scans[0].scan_id} ({start.x:.3f}, {start.y:.3f} m) "
                        f"lies outside the map's known area (bounds {b} m)")


def map_for(scenario: Scenario, scan: Scan, cache: dict | None = None):
    """The map a scan is localized in: the dataset's map file, or, for a scan-to-scan dataset
    (optional ``ref_ranges`` column), the reference scan as a polyline map with the reference
    robot at the origin (so ``true``/``init`` are relative poses)."""
    if scan.ref_ranges is not None:
        from tfloc.maps.scanmap import polyline_map_from_scan

        return polyline_map_from_scan(scan.ref_ranges, scenario.laser)
    cache = {} if cache is None else cache
    if scenario.map_path not in cache:
        from tfloc.io.maps import load_map

        cache[scenario.map_path] = load_map(scenario.map_path)
    return cache[scenario.map_path]


def read_scans(scenario: Scenario) -> list[Scan]:
    """All scans of a dataset (validated)."""
    return list(iter_scans(scenario))


def _fmt(v: float) -> str:
    return "inf" if math.isinf(v) else ("nan" if math.isnan(v) else f"{v:.4f}".rstrip("0").rstrip("."))


def _pose_text(p: Pose | None) -> list[str]:
    return ["", "", ""] if p is None else [f"{p.x:.6f}", f"{p.y:.6f}", f"{p.theta:.7f}"]


def write_scenario(root: str | Path, name: str, map_path: str | Path, laser: LaserSpec,
                   scans: Iterable[Scan], description: str = "", **extra) -> Path:
    """Write a dataset directory (``scenario.json`` + ``scans.csv``); ``map_path`` is stored
    relative to ``root``. Ranges are written with 0.1 mm precision; a ``stamp`` column (µs) is
    written only if some scan has a stamp."""
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    rel = Path(os.path.relpath(Path(map_path).resolve(), root.resolve()))
    doc = {"name": name, "map": rel.as_posix(), "description": description, "units": "metres, radians",
           "laser": {"max_range": laser.max_range, "fov_deg": round(math.degrees(laser.fov), 9),
                     "resolution_deg": round(math.degrees(laser.resolution), 9),
                     "angle_min_deg": round(math.degrees(laser.angle_min), 9)}, **extra}
    (root / "scenario.json").write_text(json.dumps(doc, indent=2) + "\n")
    scans = list(scans)
    with_ref = any(s.ref_ranges is not None for s in scans)
    with_stamp = any(s.stamp is not None for s in scans)
    with_odom = any(s.odom is not None for s in scans)
    with (root / "scans.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS + (["stamp"] if with_stamp else []) + (ODOM_COLUMNS if with_odom else [])
                   + (["ref_ranges"] if with_ref else []))
        for s in scans:
            ref = [] if not with_ref else [" ".join(_fmt(v) for v in s.ref_ranges)
                                           if s.ref_ranges is not None else ""]
            stamp = [] if not with_stamp else ["" if s.stamp is None else f"{s.stamp:.6f}"]
            odom = [] if not with_odom else _pose_text(s.odom)
            w.writerow([s.scan_id, s.group, *_pose_text(s.true), *_pose_text(s.initial),
                        " ".join(_fmt(v) for v in s.ranges), *stamp, *odom, *ref])
    return root


@lru_cache(maxsize=16)
def load_dataset(path: str) -> tuple[Scenario, dict[str, Scan]]:
    """A dataset's metadata and scans by id, read once per process (:func:`read_scenario`,
    :func:`read_scans`)."""
    scenario = read_scenario(path)
    return scenario, {s.scan_id: s for s in read_scans(scenario)}
