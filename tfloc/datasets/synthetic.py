"""Scenario datasets of the paper's protocol: true and initial poses in free space, noisy scans.

Every scan belongs to a cell of the protocol's 3 × 3 offset grid (:mod:`tfloc.datasets.protocol`,
which also draws the initial pose). Both poses lie in free space with a clearance (default
0.3 m). The real scan is the map's raycast from the true pose plus
:class:`~tfloc.datasets.noise.NoiseModel` noise.

The bundle (:func:`generate_bundle`) is drawn from one master seed, with one child seed per
dataset (``numpy.random.SeedSequence.spawn``), so it is reproducible bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.errors import ConfigError
from tfloc.io.geojson import read_vector_map, write_vector_map
from tfloc.io.scenario import Scan, write_scenario
from tfloc.maps.vector import VectorMap

from .noise import NoiseModel
from .offices import OFFICES
from .protocol import Stratum, initial_pose, strata

MASTER_SEED = 20261122


def sample_free_pose(m: VectorMap, rng: np.random.Generator, clearance: float) -> Pose:
    """A pose uniform over the map's free space (``clearance`` metres from geometry), heading uniform."""
    x0, y0, x1, y1 = m.bounds
    while True:
        xy = rng.uniform((x0, y0), (x1, y1), size=(64, 2))
        th = rng.uniform(-math.pi, math.pi, size=64)
        ok = np.flatnonzero(m.is_free(xy, clearance))
        if ok.size:
            k = ok[0]
            return Pose(float(xy[k, 0]), float(xy[k, 1]), float(th[k]))


def sample_pose_pair(m: VectorMap, cell: Stratum, rng: np.random.Generator,
                     clearance: float = 0.3, tries: int = 64) -> tuple[Pose, Pose]:
    """A true pose and an initial pose (VP) offset from it as ``cell`` prescribes, both free."""
    while True:
        true = sample_free_pose(m, rng, clearance)
        init = initial_pose(true, cell, rng, lambda xy: m.is_free(xy, clearance), tries)
        if init is not None:
            return true, init


def sample_scans(m: VectorMap, laser: LaserSpec, noise: NoiseModel, per_cell: int,
                 rng: np.random.Generator, clearance: float = 0.3) -> list[Scan]:
    """``per_cell`` scans in each of the nine cells, ids ``<cell>-<k>``, groups = cell labels."""
    scans = []
    for cell in strata():
        for k in range(per_cell):
            true, init = sample_pose_pair(m, cell, rng, clearance)
            ranges = noise.apply(m.raycast(true, laser), laser, rng)
            scans.append(Scan(f"{cell.label}-{k:03d}", cell.label, ranges, init, true))
    return scans


@dataclass(frozen=True)
class BundleSpec:
    """What :func:`generate_bundle` writes: the office-2 pool and one dataset per detail level."""

    seed: int = MASTER_SEED
    pool_per_cell: int = 180   # 9 × 180 = 1620 scans (Scenarios II and III)
    detail_per_cell: int = 60  # 9 × 60 = 540 scans per detail level (Scenario I)
    noise: NoiseModel = NoiseModel()
    clearance_m: float = 0.3
    laser: LaserSpec = LaserSpec.lms200()

    def __post_init__(self) -> None:
        if self.pool_per_cell < 1 or self.detail_per_cell < 1:
            raise ConfigError("scans per cell must be ≥ 1")
        if self.clearance_m < 0:
            raise ConfigError(f"clearance must be ≥ 0 m, got {self.clearance_m}")


def generate_bundle(out: str | Path, spec: BundleSpec = BundleSpec(), log=None) -> list[Path]:
    """Write ``out/maps/office-{1,2,3}.geojson`` and the datasets ``out/scenarios/office-pool``,
    ``detail-1``, ``detail-2``, ``detail-3``. Returns the dataset directories."""
    out = Path(out)
    (out / "maps").mkdir(parents=True, exist_ok=True)
    maps = {}
    for level, build in OFFICES.items():
        path = out / "maps" / f"office-{level}.geojson"
        write_vector_map(build(), path)
        maps[level] = (path, read_vector_map(path))  # sample on the map exactly as stored
    jobs = [("office-pool", 2, spec.pool_per_cell,
             "Scenarios II and III: one pool on the furnished office (level 2), "
             "binned by initial angle offset (II) or initial distance offset (III)", ["II", "III"])]
    jobs += [(f"detail-{lv}", lv, spec.detail_per_cell,
              f"Scenario I: environmental detail level {lv} (office-{lv})", ["I"]) for lv in (1, 2, 3)]
    seeds = np.random.SeedSequence(spec.seed).spawn(len(jobs))
    dirs = []
    for (name, level, per_cell, desc, paper), ss in zip(jobs, seeds, strict=True):
        path, m = maps[level]
        scans = sample_scans(m, spec.laser, spec.noise, per_cell, np.random.default_rng(ss),
                             spec.clearance_m)
        root = out / "scenarios" / name
        write_scenario(root, name, path, spec.laser, scans, description=desc, paper_scenarios=paper,
                       generator={"seed": spec.seed, "child": int(ss.spawn_key[-1]),
                                  "per_cell": per_cell, "clearance_m": spec.clearance_m,
                                  "noise": spec.noise.record()})
        dirs.append(root)
        if log:
            log(f"{root}: {len(scans)} scans on {path.name}")
    return dirs
