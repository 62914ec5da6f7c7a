"""The changed-world datasets: the furnished office's map, scans of a world that differs from it.

``changed-clutter-{0,10,25}``: unmapped people and boxes occluding 0, 10 and 25 % of the beams
(:mod:`tfloc.datasets.clutter`); ``changed-furniture-gone``: the furniture is gone from the world
and kept in the map. All four share the true and initial poses (the protocol's 3 × 3 offset
cells, poses free in the map), the laser (LMS200) and the range noise of the bundle, so a
matcher's success can be compared level by level, scan by scan. They are drawn from their own
seed sequence (``[seed, 25]``), so the bundle's datasets are unchanged.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tfloc.io.geojson import read_vector_map
from tfloc.io.scenario import Scan, write_scenario

from .clutter import ClutterSpec, occlude, occluded_share
from .protocol import strata
from .synthetic import BundleSpec, sample_pose_pair

#: Occluded shares of the clutter datasets.
LEVELS = (0.0, 0.10, 0.25)
#: Scans per offset cell of every changed-world dataset (9 × 60 = 540).
PER_CELL = 60
ISSUE_KEY = 25


def generate_changed_world(out: str | Path, spec: BundleSpec | None = None, per_cell: int = PER_CELL,
                           log=None) -> list[Path]:
    """Write ``out/scenarios/changed-clutter-{0,10,25}`` and ``changed-furniture-gone`` (the maps
    ``out/maps/office-{1,2}.geojson`` must exist: :func:`tfloc.datasets.synthetic.generate_bundle`)."""
    out, spec = Path(out), spec or BundleSpec()
    map_path = out / "maps" / "office-2.geojson"
    office, bare = read_vector_map(map_path), read_vector_map(out / "maps" / "office-1.geojson")
    ss_poses, ss_noise, *ss_levels = np.random.SeedSequence([spec.seed, ISSUE_KEY]).spawn(2 + len(LEVELS))
    rng = np.random.default_rng(ss_poses)
    cells = [(c, k) for c in strata() for k in range(per_cell)]
    pairs = [sample_pose_pair(office, c, rng, spec.clearance_m) for c, _ in cells]
    jobs = [(f"changed-clutter-{round(100 * s)}", office, ClutterSpec(s), ss, f"clutter-{round(100 * s)}")
            for s, ss in zip(LEVELS, ss_levels, strict=True)]
    jobs.append(("changed-furniture-gone", bare, ClutterSpec(0.0), None, "furniture-gone"))
    dirs = []
    for name, world, cspec, ss, style in jobs:
        obj_rng = np.random.default_rng(ss) if ss is not None else None
        noise_rng = np.random.default_rng(ss_noise)  # the same noise draws for every dataset
        scans, shares = [], []
        for (cell, k), (true, init) in zip(cells, pairs, strict=True):
            if obj_rng is not None:
                ideal, _ = occlude(world, true, spec.laser, cspec, obj_rng)
            else:
                ideal = world.raycast(true, spec.laser)
            shares.append(occluded_share(office.raycast(true, spec.laser), ideal) if style != "furniture-gone"
                          else float(np.mean(ideal != office.raycast(true, spec.laser))))
            ranges = spec.noise.apply(ideal, spec.laser, noise_rng)
            scans.append(Scan(f"{cell.label}-{k:03d}", cell.label, ranges, init, true))
        q = np.percentile(shares, [0, 50, 100])
        within = (int(np.sum(np.abs(np.array(shares) - cspec.share) <= cspec.tolerance + 1e-9))
                  if style.startswith("clutter") else None)
        desc = ("A changed world on the furnished office (map office-2): "
                + (f"unmapped people (0.3 m discs) and boxes (0.3-0.6 m) occluding {cspec.share:.0%} of the "
                   f"beams (within {cspec.tolerance:.0%}) " if style.startswith("clutter") else
                   "the furniture is gone from the world (scans simulated in office-1) and kept in the map ")
                + f"; {len(scans)} scans, poses shared by all changed-* datasets; LMS200, sigma "
                  f"{spec.noise.sigma_m:g} m. Beams changed per scan: min {q[0]:.1%}, median {q[1]:.1%}, "
                  f"max {q[2]:.1%}.")
        root = out / "scenarios" / name
        write_scenario(root, name, map_path, spec.laser, scans, description=desc,
                       axis={"log": "office-sim", "style": style},
                       generator={"command": "tfloc generate", "seed": spec.seed, "seed_key": ISSUE_KEY,
                                  "per_cell": per_cell, "clearance_m": spec.clearance_m,
                                  "occluded_share": cspec.share, "tolerance": cspec.tolerance,
                                  "changed_beams": {"min": round(float(q[0]), 4), "median": round(float(q[1]), 4),
                                                    "max": round(float(q[2]), 4),
                                                    "within_tolerance": within},
                                  "noise": {"sigma_m": spec.noise.sigma_m}})
        dirs.append(root)
        if log:
            log(f"{root}: {len(scans)} scans on {map_path.name}")
    return dirs
