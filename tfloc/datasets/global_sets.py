"""Global-localization datasets (``"mode": "global"``): no initial guess, the pose is searched over
the whole map.

* ``global-office-{1,2,3}`` (evaluation): :data:`OFFICE_SCANS` = 500 simulated LMS200 scans per
  office floor, true poses uniform over the free space (≥ 0.3 m from geometry,
  :func:`~tfloc.datasets.synthetic.sample_free_pose`), heading uniform, the protocol's range
  noise (:class:`~tfloc.datasets.noise.NoiseModel`, σ = 1 cm).
* ``real-{intel,csail,aces}-global`` (evaluation): every real scan of the SLAM-corrected log with
  its corrected pose as truth (group ``real``), topped up to :data:`REAL_MIN_SCANS` = 500 with
  scans ray-cast in the log's grid map at poses uniform over its known free space (group
  ``sim``, same noise). CSAIL has 406 and ACES 440 real scans: the real scans are kept whole
  (they are the point of a real map), and the simulated ones, reported apart by their group,
  spread the poses over rooms the robot's path only passed by. Intel (910 scans) is all real.
* ``global-dev-office-{1,2,3}`` and ``global-dev-real-{intel,csail,aces}`` (development, for
  tuning): :data:`DEV_SCANS` = 50 simulated scans each from other seeds; the real maps' dev sets
  are simulated only, so no real scan an evaluation set holds is ever tuned on.

Every dataset draws from its own generator (``SeedSequence([seed, split, index])``), so the
datasets regenerate bit for bit and adding one leaves the others unchanged.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.io.carmen import read_carmen
from tfloc.io.geojson import read_vector_map
from tfloc.io.maps import load_map
from tfloc.io.scenario import GLOBAL, Scan, write_scenario

from .noise import NoiseModel
from .real import REAL_LOGS, clean_ranges, front_scans
from .synthetic import sample_free_pose

GLOBAL_SEED = 20261201
OFFICE_SCANS = 500
REAL_MIN_SCANS = 500
DEV_SCANS = 50
CLEARANCE_M = 0.3
EVAL, DEV = 0, 1  # the split, part of every dataset's seed
NOISE = NoiseModel()  # the protocol's: sigma 1 cm
LMS200 = LaserSpec.lms200()


def _rng(seed: int, split: int, index: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed, split, index]))


def simulated_scans(m: Map, laser: LaserSpec, noise: NoiseModel, n: int, rng: np.random.Generator,
                    clearance: float = CLEARANCE_M, prefix: str = "g", group: str = "sim") -> list[Scan]:
    """``n`` global scans (no initial guess): true poses uniform over ``m``'s free space, ranges
    ray-cast from them plus ``noise``; a pose whose scan has fewer than 10 returns is redrawn."""
    scans: list[Scan] = []
    while len(scans) < n:
        true = sample_free_pose(m, rng, clearance)
        ranges = noise.apply(m.raycast(true, laser), laser, rng)
        if int(laser.valid(ranges).sum()) < 10:
            continue
        scans.append(Scan(f"{prefix}{len(scans):04d}", group, ranges, None, true))
    return scans


def _generator(seed: int, split: int, index: int, noise: NoiseModel, **extra) -> dict:
    return {"seed": seed, "split": "evaluation" if split == EVAL else "development", "index": index,
            "clearance_m": CLEARANCE_M, "noise": noise.record(), **extra}


def generate_global_offices(out: str | Path, seed: int = GLOBAL_SEED, n: int = OFFICE_SCANS,
                            n_dev: int = DEV_SCANS, noise: NoiseModel = NOISE,
                            laser: LaserSpec = LMS200, log=None) -> list[Path]:
    """Write ``out/scenarios/global-office-{1,2,3}`` (evaluation) and ``global-dev-office-{1,2,3}``
    (development) on the office maps ``out/maps/office-{1,2,3}.geojson`` (written by
    :func:`~tfloc.datasets.synthetic.generate_bundle`). Returns the dataset directories."""
    out = Path(out)
    dirs = []
    for split, count, name in ((EVAL, n, "global-office-{lv}"), (DEV, n_dev, "global-dev-office-{lv}")):
        for lv in (1, 2, 3):
            path = out / "maps" / f"office-{lv}.geojson"
            m = read_vector_map(path)
            scans = simulated_scans(m, laser, noise, count, _rng(seed, split, lv))
            ds = name.format(lv=lv)
            use = "evaluation" if split == EVAL else "development (tuning only)"
            dirs.append(write_scenario(
                out / "scenarios" / ds, ds, path, laser, scans, mode=GLOBAL,
                description=(f"Global localization on office-{lv} ({use} split): {count} simulated "
                             "LMS200 scans, no initial guess; true poses uniform over the free space "
                             f"(>= {CLEARANCE_M:g} m from geometry), heading uniform, range noise "
                             f"sigma {noise.sigma_m:g} m."),
                generator=_generator(seed, split, lv, noise, command="tfloc generate")))
            if log:
                log(f"{dirs[-1]}: {count} global scans on {path.name}")
    return dirs


def real_global_scans(log_path: Path, laser: LaserSpec, no_return: float, grid: Map,
                      min_scans: int, rng: np.random.Generator, noise: NoiseModel) -> list[Scan]:
    """Every front-laser scan of a corrected log (truth = its corrected pose, group ``real``),
    then simulated scans in ``grid`` (group ``sim``) up to ``min_scans``."""
    records = front_scans(read_carmen(log_path), laser)
    rows = [Scan(f"r{k:04d}", "real", clean_ranges(s.ranges, no_return), None, s.pose)
            for k, s in enumerate(records)]
    rows += simulated_scans(grid, laser, noise, max(0, min_scans - len(rows)), rng, prefix="s")
    return rows


def build_global_real(real: str | Path, out: str | Path, seed: int = GLOBAL_SEED,
                      min_scans: int = REAL_MIN_SCANS, n_dev: int = DEV_SCANS,
                      noise: NoiseModel = NOISE, log=None) -> list[Path]:
    """Write ``out/scenarios/real-{key}-global`` (evaluation) and ``global-dev-real-{key}``
    (development, simulated only) for the Intel, MIT CSAIL and ACES logs, on their grid maps
    ``out/maps/real-{key}.yaml`` (written by :func:`~tfloc.datasets.real.build_all`)."""
    real, out = Path(real), Path(out)
    dirs = []
    for index, (key, log_rel, laser, no_return) in enumerate(REAL_LOGS, start=1):
        map_yaml = out / "maps" / f"real-{key}.yaml"
        grid = load_map(map_yaml)
        rows = real_global_scans(real / log_rel, laser, no_return, grid, min_scans,
                                 _rng(seed, EVAL, 10 + index), noise)
        n_real = sum(r.group == "real" for r in rows)
        name = f"real-{key}-global"
        dirs.append(write_scenario(
            out / "scenarios" / name, name, map_yaml, laser, rows, mode=GLOBAL,
            description=(f"Global localization on the {key} grid map (evaluation split): all {n_real} "
                         "real scans of the SLAM-corrected log (group 'real', truth = corrected pose), "
                         f"plus {len(rows) - n_real} scans ray-cast in the grid at poses uniform over its "
                         f"known free space (group 'sim', >= {CLEARANCE_M:g} m from occupied cells, "
                         f"noise sigma {noise.sigma_m:g} m); no initial guess."),
            generator=_generator(seed, EVAL, 10 + index, noise, command="tfloc real-data"),
            source={"files": [f"data/real/{log_rel}"], "provenance": "data/real/*/PROVENANCE.md"}))
        dev = f"global-dev-real-{key}"
        scans = simulated_scans(grid, laser, noise, n_dev, _rng(seed, DEV, 10 + index))
        dirs.append(write_scenario(
            out / "scenarios" / dev, dev, map_yaml, laser, scans, mode=GLOBAL,
            description=(f"Global localization on the {key} grid map (development split, tuning only): "
                         f"{n_dev} scans ray-cast in the grid at poses uniform over its known free space; "
                         "no real scan (those are all in the evaluation set)."),
            generator=_generator(seed, DEV, 10 + index, noise, command="tfloc real-data")))
        if log:
            log(f"{dirs[-2]}: {len(rows)} scans ({n_real} real); {dirs[-1]}: {n_dev}")
    return dirs
