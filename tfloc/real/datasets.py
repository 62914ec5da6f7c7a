"""Scenario datasets built from the real logs in ``data/real/`` (deterministic for a given seed).

* ``real-csail-relations``: scan-to-scan on the MIT CSAIL log and the 1172 relations of
  Kümmerle et al. (2009): the scan at t2 (``ranges``) against the scan at t1 (``ref_ranges``),
  ``true`` = the relation, ``init`` = the raw odometry between the two scans.
* ``real-intel-scan-to-map``, ``real-csail-scan-to-map`` and ``real-aces-scan-to-map``: every scan
  of a SLAM-corrected log localized in a grid map built from all corrected scans, from an initial
  pose perturbed in the paper's 3 × 3 offset bins.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DatasetError
from ..harness.dataset import Scan, write_scenario
from ..io.carmen import CarmenLog, read_carmen
from ..io.relations import join_relations, read_relations
from ..io.rosmap import write_ros_map
from ..laser import LaserSpec
from ..maps.build import grid_from_scans
from ..maps.grid import GridMap
from ..pose import Pose

#: Ranges at or above this are the logs' no-return code (81.83–81.91 m).
NO_RETURN_M = 80.0
#: Largest range kept. The CSAIL logs record ``PARAM robot_front_laser_max 50``; the largest real
#: returns are 42.40 m (CSAIL) and 25.38 m (Intel), so 50 m drops no real return.
MAX_RANGE_M = 50.0
#: Paper's offset bins: distance (m) × orientation (rad).
DIST_BINS_M = ((0.0, 1.0), (1.0, 2.0), (2.0, 3.0))
ANGLE_BINS_RAD = tuple((math.radians(a), math.radians(b)) for a, b in ((0, 5), (5, 10), (10, 15)))
DEFAULT_SEED = 20091122

CSAIL_LASER = LaserSpec.from_degrees(MAX_RANGE_M, 180.0, 0.5, -90.0)
#: Intel: 180 beams at 1° from -90° (-90°…+89°), settled by measurement (data/real/intel/SPACING.md).
INTEL_LASER = LaserSpec.from_degrees(MAX_RANGE_M, 179.0, 1.0, -90.0)
#: ACES: 180 beams at 1° from -90°, settled by the same measurement (data/real/aces/SPACING.md).
ACES_LASER = LaserSpec.from_degrees(MAX_RANGE_M, 179.0, 1.0, -90.0)
#: The ACES log caps its ranges at 50 m: exactly 50 m is its no-return code (620 beams; the
#: largest real return is 49.91 m).
ACES_NO_RETURN_M = 50.0


def clean_ranges(ranges: np.ndarray, no_return: float = NO_RETURN_M) -> np.ndarray:
    """The no-return code (ranges ≥ ``no_return`` metres) → ``inf``; metres."""
    r = np.array(ranges, dtype=float)
    r[r >= no_return] = np.inf
    return r


def _front(log: CarmenLog, laser: LaserSpec) -> list:
    scans = [s for s in log.lasers if s.kind == "FLASER"]
    bad = [s for s in scans if len(s.ranges) != laser.n_beams]
    if bad:
        raise DatasetError(f"{log.path}:{bad[0].line}: {len(bad[0].ranges)} beams, expected {laser.n_beams}")
    return scans


def relations_scans(clf: Path, relations: Path, laser: LaserSpec = CSAIL_LASER,
                    loop_gap_s: float = 5.0) -> list[Scan]:
    """One scan-to-scan row per relation (in file order); ``scan_id`` = ``rel<line>``.

    ``group`` is ``local`` if t2 − t1 ≤ ``loop_gap_s`` seconds, else ``loop`` (a revisit: the
    odometry between the scans has drifted, often by metres)."""
    log = read_carmen(clf)
    scans = _front(log, laser)
    rels = read_relations(relations)
    idx = join_relations(rels, scans, relations)
    rows = []
    for rel, (i, j) in zip(rels, idx, strict=True):
        a, b = scans[i], scans[j]
        rows.append(Scan(f"rel{rel.line:04d}", "local" if abs(rel.t2 - rel.t1) <= loop_gap_s else "loop",
                         clean_ranges(b.ranges), a.odom.between(b.odom), rel.delta,
                         ref_ranges=clean_ranges(a.ranges)))
    return rows


@dataclass(frozen=True)
class Perturbation:
    """How initial poses are drawn: the bins, the free-space clearance (m) and the seed."""

    seed: int = DEFAULT_SEED
    clearance_m: float = 0.2
    max_tries: int = 10000


def perturb(truth: np.ndarray, grid: GridMap, cfg: Perturbation) -> tuple[np.ndarray, list[str]]:
    """Initial poses ``(N, 3)`` and groups ``d{i}-a{j}``: scan k gets bin ``perm[k] mod 9`` (a
    seeded balanced assignment), a distance and an angle magnitude uniform in that bin, a uniform
    direction and a random sign; redrawn until the position is free (``clearance_m``) and in
    bounds."""
    rng = np.random.default_rng(cfg.seed)
    n = len(truth)
    bins = rng.permutation(n) % (len(DIST_BINS_M) * len(ANGLE_BINS_RAD))
    init = np.empty((n, 3))
    groups = []
    for k in range(n):
        di, ai = divmod(int(bins[k]), len(ANGLE_BINS_RAD))
        (d0, d1), (a0, a1) = DIST_BINS_M[di], ANGLE_BINS_RAD[ai]
        for _ in range(cfg.max_tries):
            d, phi = rng.uniform(d0, d1), rng.uniform(-math.pi, math.pi)
            xy = truth[k, :2] + d * np.array([math.cos(phi), math.sin(phi)])
            if grid.in_bounds(xy)[0] and grid.is_free(xy, cfg.clearance_m)[0]:
                break
        else:
            raise DatasetError(f"scan {k}: no free initial position in bin d{di + 1} after {cfg.max_tries} draws")
        dth = rng.uniform(a0, a1) * rng.choice((-1.0, 1.0))
        init[k] = (xy[0], xy[1], math.atan2(math.sin(truth[k, 2] + dth), math.cos(truth[k, 2] + dth)))
        groups.append(f"d{di + 1}-a{ai + 1}")
    return init, groups


def scan_to_map(log_path: Path, laser: LaserSpec, resolution: float = 0.05,
                cfg: Perturbation = Perturbation(),
                no_return: float = NO_RETURN_M) -> tuple[GridMap, list[Scan]]:
    """The grid map of a corrected log and its scans with perturbed initial poses (ranges ≥
    ``no_return`` metres are the log's no-return code)."""
    log = read_carmen(log_path)
    scans = _front(log, laser)
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
    """(Re)build the four real datasets under ``out/scenarios`` and their maps under ``out/maps``.

    Each scan-to-map set draws its initial poses from its own generator seeded with ``seed``, so
    adding a log leaves the others' datasets byte-identical."""
    real, out = Path(real), Path(out)
    made = []
    csail = real / "mit-csail"
    rel_root = out / "scenarios" / "real-csail-relations"
    rows = relations_scans(csail / "mit-csail.clf.gz", csail / "mit-csail.relations")
    made.append(write_scenario(
        rel_root, "real-csail-relations", real / "mit-csail" / "mit-csail.clf.gz", CSAIL_LASER, rows,
        description=(
            "Scan-to-scan on MIT CSAIL (Stata Center) with the 1172 ground-truth relations of Kümmerle "
            "et al. 2009. Row = one relation (scan_id rel<line of mit-csail.relations>): ranges = FLASER "
            "scan at t2, ref_ranges = scan at t1, true = relation (pose at t2 in the frame at t1), init = "
            "raw odometry between the two scans. The map is the reference scan (tfloc.harness.dataset."
            "map_for); the 'map' field names the source log only. group: local (t2-t1 <= 5 s) or loop "
            "(revisit, odometry drifted). No-return 81.91 m -> inf; max_range 50 m (PARAM "
            "robot_front_laser_max 50; largest real return 42.40 m). Note: in 534 relations the "
            "translation equals the odometry's to < 0.1 mm; most others differ from it by 5, 7.1 or "
            "11.2 cm (5 cm x sqrt(k)), so the ground truth looks quantised at about 5 cm."),
        scan_to_scan=True, source=_source(real, "mit-csail/mit-csail.clf.gz", "mit-csail/mit-csail.relations")))
    cfg = Perturbation(seed=seed)
    aces_note = (
        "ACES building, UT Austin (440 scans, 180 beams at 1 deg from -90 deg: see "
        "data/real/aces/SPACING.md; the log caps ranges at 50 m, and 50 m is its no-return code)")
    for key, log_rel, laser, note, no_return in (
            ("intel", "intel/intel-corrected.log.gz", INTEL_LASER,
             "Intel Research Lab (910 scans, 180 beams at 1 deg from -90 deg: see data/real/intel/SPACING.md)",
             NO_RETURN_M),
            ("csail", "mit-csail/csail-corrected.log.gz", CSAIL_LASER,
             "MIT CSAIL corrected log (406 scans, 361 beams at 0.5 deg)", NO_RETURN_M),
            ("aces", "aces/aces-corrected.log.gz", ACES_LASER, aces_note, ACES_NO_RETURN_M)):
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
