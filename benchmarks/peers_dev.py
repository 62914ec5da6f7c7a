"""Development-split measurements behind the configurations of ``gicp`` and ``karto``.

The split: office-pool scans 100–139 of each of the nine offset cells (360 scans), disjoint from
the scans the benchmarks use (0–19 per cell). For each matcher, its configuration and one-change
variants (as keyword overrides): success (≤ 10 cm and ≤ 2°) overall and by offset bin 0–1 / 1–2 /
2–3 m, median errors when successful, and CPU ms per ``localize`` (``time.process_time``, one
process, per-map caches built before the timing).

Run::

    .venv/bin/python benchmarks/peers_dev.py gicp
    .venv/bin/python benchmarks/peers_dev.py karto
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import tfloc
from tfloc import Pose, Problem, angdiff
from tfloc.io.scenario import iter_scans, map_for, read_scenario

ROOT = Path(__file__).resolve().parents[1]

VARIANTS = {
    "gicp": [("configuration", {}),
             ("ICP", {"registration_type": "ICP"}), ("PLANE_ICP", {"registration_type": "PLANE_ICP"}),
             ("z = 0, GICP", {"layers": [0.0]}), ("z = 0, ICP", {"layers": [0.0], "registration_type": "ICP"}),
             ("z = 0, PLANE_ICP", {"layers": [0.0], "registration_type": "PLANE_ICP"}),
             ("layers ±0.1 m", {"layers": [-0.1, 0.0, 0.1]}), ("layers ±0.2 m", {"layers": [-0.2, 0.0, 0.2]}),
             ("one 1 m gate", {"gates": [1.0]}), ("gates from 1 m", {"gates": [1.0, 0.5, 0.2, 0.1]}),
             ("gates from 3 m", {"gates": [3.0, 2.0, 1.0, 0.5, 0.2, 0.1]}),
             ("map spacing 2 cm", {"map_spacing": 0.02}), ("max_iterations 50", {"max_iterations": 50}),
             ("num_neighbors 20", {"num_neighbors": 20})],
    "karto": [("configuration", {}),
              ("base_radius 2 m", {"base_radius": 2.0}), ("base_radius 6 m", {"base_radius": 6.0}),
              ("lattice 0.5 m", {"lattice_spacing": 0.5}), ("virtual beams 0.5°", {"virtual_beam_deg": 0.5}),
              ("coarse 0.05 m, smear 0.03 m", {"coarse_resolution": 0.05, "coarse_smear_deviation": 0.03}),
              ("coarse smear 0.15 m", {"coarse_smear_deviation": 0.15}),
              ("coarse angle steps 1°", {"coarse_angle_resolution_deg": 1.0}),
              ("no angle penalty", {"minimum_angle_penalty": 1.0}),
              ("minimum distance penalty 0.5", {"minimum_distance_penalty": 0.5}),
              ("fine smear 0.05 m", {"fine_smear_deviation": 0.05})],
}


def dev_split(first: int = 100, last: int = 140) -> list[tuple[Problem, Pose, int]]:
    """``(problem, true pose, distance bin 0/1/2)`` for office-pool scans ``first``…``last - 1`` of each cell."""
    scenario = read_scenario(ROOT / "data/scenarios/office-pool")
    maps: dict = {}
    seen: dict[str, int] = {}
    out = []
    for scan in iter_scans(scenario):
        k = seen[scan.group] = seen.get(scan.group, 0) + 1
        if first < k <= last:
            problem = Problem(map_for(scenario, scan, maps), scenario.laser, scan.ranges, scan.initial)
            out.append((problem, scan.true, int(scan.group[1]) - 1))
    return out


def evaluate(matcher: tfloc.Matcher, problems: list[tuple[Problem, Pose, int]]) -> str:
    """One table row: success overall and by bin, median errors when successful, CPU ms."""
    matcher.localize(problems[0][0])  # build the per-map caches outside the timing
    rows = []
    for problem, true, dbin in problems:
        t0 = time.process_time()
        pose = matcher.localize(problem).pose
        ms = 1e3 * (time.process_time() - t0)
        rows.append((dbin, pose.distance_to(true), math.degrees(abs(angdiff(pose.theta, true.theta))), ms))
    r = np.array(rows)
    ok = (r[:, 1] <= 0.10) & (r[:, 2] <= 2.0)
    bins = " / ".join(f"{100 * ok[r[:, 0] == b].mean():.1f}" for b in range(3))
    med = f"{100 * np.median(r[ok, 1]):.2f} cm / {np.median(r[ok, 2]):.3f}°" if ok.any() else "–"
    return (f"{100 * ok.mean():.1f} | {bins} | {med} | {np.median(r[:, 3]):.1f} | "
            f"{np.percentile(r[:, 3], 95):.1f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("matcher", choices=sorted(VARIANTS))
    args = ap.parse_args()
    problems = dev_split()
    print(f"{args.matcher}: {len(problems)} development scans (office-pool 100–139 per cell)")
    print("| variant | success % | 0–1 / 1–2 / 2–3 m % | median when successful | CPU ms median | p95 |")
    print("|---|---|---|---|---|---|")
    for label, params in VARIANTS[args.matcher]:
        print(f"| {label} | {evaluate(tfloc.get_matcher(args.matcher, **params), problems)} |", flush=True)


if __name__ == "__main__":
    main()
