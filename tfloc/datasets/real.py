"""Scenario datasets built from the real logs in ``data/real/`` (deterministic for a given seed).

* the MIT CSAIL relations datasets: :mod:`tfloc.datasets.relations`.
* ``real-intel-scan-to-map``, ``real-csail-scan-to-map`` and ``real-aces-scan-to-map``: every scan
  of a SLAM-corrected log localized in a grid map built from all corrected scans, from an initial
  pose perturbed in the paper's 3 × 3 offset bins.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.errors import DatasetError
from tfloc.io.carmen import CarmenLog, read_carmen
from tfloc.io.rosmap import write_ros_map
from tfloc.io.scenario import Scan, write_scenario
from tfloc.maps.build import grid_from_scans
from tfloc.maps.grid import GridMap

from .protocol import DEFAULT_SEED, Perturbation, perturb

#: Ranges at or above this are the logs' no-return code (81.83–81.91 m).
NO_RETURN_M = 80.0
#: Largest range kept. The CSAIL logs record ``PARAM robot_front_laser_max 50``; the largest real
#: returns are 42.40 m (CSAIL) and 25.38 m (Intel), so 50 m drops no real return.
MAX_RANGE_M = 50.0

CSAIL_LASER = LaserSpec.from_degrees(MAX_RANGE_M, 180.0, 0.5, -90.0)
#: Intel: 180 beams at 1° from -90° (-90°…+89°), settled by measurement (data/real/intel/SPACING.md).
INTEL_LASER = LaserSpec.from_degrees(MAX_RANGE_M, 179.0, 1.0, -90.0)
#: ACES: 180 beams at 1° from -90°, settled by the same measurement (data/real/aces/SPACING.md).
ACES_LASER = LaserSpec.from_degrees(MAX_RANGE_M, 179.0, 1.0, -90.0)
#: The ACES log caps its ranges at 50 m: exactly 50 m is its no-return code (620 beams; the
#: largest real return is 49.91 m).
ACES_NO_RETURN_M = 50.0

#: The bundled corrected logs: (key, path under ``data/real``, laser, no-return range in metres)
REAL_LOGS = (("intel", "intel/intel-corrected.log.gz", INTEL_LASER, NO_RETURN_M),
             ("csail", "mit-csail/csail-corrected.log.gz", CSAIL_LASER, NO_RETURN_M),
             ("aces", "aces/aces-corrected.log.gz", ACES_LASER, ACES_NO_RETURN_M))


def clean_ranges(ranges: np.ndarray, no_return: float = NO_RETURN_M) -> np.ndarray:
    """The no-return code (ranges ≥ ``no_return`` metres) → ``inf``; metres."""
    r = np.array(ranges, dtype=float)
    r[r >= no_return] = np.inf
    return r


def front_scans(log: CarmenLog, laser: LaserSpec) -> list:
    """The front-laser (FLASER) records of a log, all of ``laser``'s beam count."""
    scans = [s for s in log.lasers if s.kind == "FLASER"]
    bad = [s for s in scans if len(s.ranges) != laser.n_beams]
    if bad:
        raise DatasetError(f"{log.path}:{bad[0].line}: {len(bad[0].ranges)} beams, expected {laser.n_beams}")
    return scans


def scan_to_map(log_path: Path, laser: LaserSpec, resolution: float = 0.05,
                cfg: Perturbation | None = None,
                no_return: float = NO_RETURN_M) -> tuple[GridMap, list[Scan]]:
    """The grid map of a corrected log and its scans with perturbed initial poses (ranges ≥
    ``no_return`` metres are the log's no-return code)."""
    cfg = cfg or Perturbation()
    log = read_carmen(log_path)
    scans = front_scans(log, laser)
    R = np.vstack([clean_ranges(s.ranges, no_return) for s in scans])
    P = np.array([s.pose.as_array() for s in scans])
    grid = grid_from_scans(R, P, laser, resolution, name=log_path.name.split(".")[0])
    init, groups = perturb(P, grid, cfg)
    rows = [Scan(f"s{k:04d}", g, R[k], Pose.from_array(init[k]), Pose.from_array(P[k]))
            for k, g in enumerate(groups)]
    return grid, rows


def _source(real: Path, *files: str) -> dict:
    return {"files": [f"data/real/{f}" for f in files], "provenance": "data/real/*/PROVENANCE.md"}


def build_all(real: Path, out: Path, seed: int = DEFAULT_SEED, resolution: float = 0.05) -> list[Path]:
    """(Re)build the real scan-to-map datasets under ``out/scenarios`` and their maps under
    ``out/maps`` (the relations datasets: :func:`tfloc.datasets.relations.build_relations`).
    Every log's initial poses are drawn from their own generator seeded with ``seed``, so adding
    a log leaves the others' datasets byte-identical."""
    real, out = Path(real), Path(out)
    made = []
    cfg = Perturbation(seed=seed)
    notes = {
        "intel": "Intel Research Lab (910 scans, 180 beams at 1 deg from -90 deg: see "
                 "data/real/intel/SPACING.md)",
        "csail": "MIT CSAIL corrected log (406 scans, 361 beams at 0.5 deg)",
        "aces": "ACES building, UT Austin (440 scans, 180 beams at 1 deg from -90 deg: see "
                "data/real/aces/SPACING.md; the log caps ranges at 50 m, and 50 m is its no-return code)"}
    for key, log_rel, laser, no_return in REAL_LOGS:
        note = notes[key]
        grid, rows = scan_to_map(real / log_rel, laser, resolution, cfg, no_return)
        map_yaml = write_ros_map(grid, out / "maps" / f"real-{key}.yaml")
        root = out / "scenarios" / f"real-{key}-scan-to-map"
        made.append(write_scenario(
            root, f"real-{key}-scan-to-map", map_yaml, laser, rows,
            description=(
                f"Scan-to-map on {note}. All scans of the SLAM-corrected log, true = corrected pose "
                f"(pseudo ground truth, a few cm). Map: occupancy grid at {resolution:g} m built from all "
                "corrected scans (each scan's own returns included), hit counting with free-space "
                "carving, occupied if > 25 % of the beams reaching a cell end there. init = true pose "
                "perturbed in the paper's 3x3 bins (0-1/1-2/2-3 m x 0-5/5-10/10-15 deg, groups d{i}-a{j}, "
                f"balanced), in free space >= {cfg.clearance_m:g} m from occupied cells, seed {seed}. "
                + ("No-return ~81.9 m -> inf; max_range 50 m." if no_return == NO_RETURN_M else
                   f"No-return {no_return:g} m (the log's cap) -> inf; max_range 50 m.")),
            generator={"command": "tfloc real-data", "seed": seed, "resolution_m": resolution,
                       "clearance_m": cfg.clearance_m},
            source=_source(real, log_rel)))
    return made
