"""Global-localization datasets (``"mode": "global"``): no initial guess, the pose is searched over
the whole map.

* ``global-office-{1,2,3}`` (evaluation): :data:`OFFICE_SCANS` = 500 simulated LMS200 scans per
  office floor, true poses uniform over the free space (≥ 0.3 m from geometry,
  :func:`~tfloc.datasets.synthetic.sample_free_pose`), heading uniform, the protocol's range
  noise (:class:`~tfloc.datasets.noise.NoiseModel`, σ = 1 cm).
* ``real-{intel,csail,aces}-global`` (evaluation) and ``global-dev-real-{intel,csail,aces}``
  (development): the SLAM-corrected logs' real scans only (truth = the corrected pose, scan
  ``r<k>`` = the log's k-th corrected scan, group ``real-<q>`` = the q-th of :data:`REAL_PARTS`
  parts of the log in time order, so that a run taking the first scans of each group samples the
  whole path, not its beginning), split by :func:`real_split`: every
  :data:`DEV_EVERY`-th corrected scan is development, the rest held out, so no real scan of an
  evaluation set is tuned on (Intel 910 → 182 + 728, MIT CSAIL 406 → 82 + 324, ACES 440 → 88 +
  352). A real-map figure comes from real scans alone: nothing simulated is mixed in.
* ``global-dev-office-{1,2,3}`` and ``global-dev-real-{intel,csail,aces}-sim`` (development,
  simulated): :data:`DEV_SCANS` = 50 simulated scans each from other seeds; the latter are ray-cast
  in the real logs' grid maps, so that a real scan's effect (clutter, people, glass) can be told
  from the map's and the index's on the same map.

Every simulated dataset draws from its own generator (``SeedSequence([seed, split, index])``), so
the datasets regenerate bit for bit and adding one leaves the others unchanged.
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
DEV_EVERY = 5  # every 5th corrected scan of a real log is development
REAL_PARTS = 5  # a real log's scans are grouped by the fifth of the log (time order) they lie in
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


def real_global_scans(log_path: Path, laser: LaserSpec, no_return: float) -> list[Scan]:
    """Every front-laser scan of a corrected log, truth = its corrected pose (scan ``r<k>`` for
    the k-th, group ``real-<q>`` for the q-th of :data:`REAL_PARTS` parts of the log)."""
    records = front_scans(read_carmen(log_path), laser)
    n = len(records)
    return [Scan(f"r{k:04d}", f"real-{k * REAL_PARTS // n + 1}", clean_ranges(s.ranges, no_return),
                 None, s.pose) for k, s in enumerate(records)]


def real_split(scans: list[Scan], every: int = DEV_EVERY) -> tuple[list[Scan], list[Scan]]:
    """(development, held-out): every ``every``-th scan (the 0th, ``every``-th, …) and the rest."""
    return scans[::every], [s for k, s in enumerate(scans) if k % every]


def build_global_real(real: str | Path, out: str | Path, seed: int = GLOBAL_SEED,
                      n_dev: int = DEV_SCANS, noise: NoiseModel = NOISE, every: int = DEV_EVERY,
                      log=None) -> list[Path]:
    """Write ``out/scenarios/real-{key}-global`` (evaluation: the held-out real scans),
    ``global-dev-real-{key}`` (development: every ``every``-th real scan) and
    ``global-dev-real-{key}-sim`` (development: ``n_dev`` scans ray-cast in the grid) for the
    Intel, MIT CSAIL and ACES logs, on their grid maps ``out/maps/real-{key}.yaml`` (written by
    :func:`~tfloc.datasets.real.build_all`)."""
    real, out = Path(real), Path(out)
    dirs = []
    for index, (key, log_rel, laser, no_return) in enumerate(REAL_LOGS, start=1):
        map_yaml = out / "maps" / f"real-{key}.yaml"
        rows = real_global_scans(real / log_rel, laser, no_return)
        dev, held = real_split(rows, every)
        source = {"files": [f"data/real/{log_rel}"], "provenance": "data/real/*/PROVENANCE.md"}
        split = (f"of its {len(rows)} SLAM-corrected scans (truth = corrected pose, scan r<k> = the "
                 f"k-th, group real-<q> = the q-th of {REAL_PARTS} parts of the log in time order); "
                 f"every {every}th (k % {every} == 0) is development, the rest held out")
        for name, scans, which, use in ((f"real-{key}-global", held, EVAL, "evaluation split: the "
                                         f"{len(held)} held-out real scans"),
                                        (f"global-dev-real-{key}", dev, DEV, "development split, tuning "
                                         f"only: the {len(dev)} development real scans")):
            dirs.append(write_scenario(
                out / "scenarios" / name, name, map_yaml, laser, scans, mode=GLOBAL,
                description=(f"Global localization on the {key} grid map ({use} {split}); real scans "
                             "only, no initial guess."),
                generator={"split": "evaluation" if which == EVAL else "development",
                           "dev_every": every, "parts": REAL_PARTS, "command": "tfloc real-data"},
                source=source))
        grid = load_map(map_yaml)
        sim = f"global-dev-real-{key}-sim"
        scans = simulated_scans(grid, laser, noise, n_dev, _rng(seed, DEV, 10 + index))
        dirs.append(write_scenario(
            out / "scenarios" / sim, sim, map_yaml, laser, scans, mode=GLOBAL,
            description=(f"Global localization on the {key} grid map (development split, tuning only): "
                         f"{n_dev} scans ray-cast in the grid at poses uniform over its known free space "
                         f"(>= {CLEARANCE_M:g} m from occupied cells, noise sigma {noise.sigma_m:g} m); "
                         "no real scan."),
            generator=_generator(seed, DEV, 10 + index, noise, command="tfloc real-data")))
        if log:
            log(f"{key}: {len(held)} held-out and {len(dev)} development real scans; {sim}: {n_dev}")
    return dirs
