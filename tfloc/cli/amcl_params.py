"""Measure the AMCL parameters a practitioner tunes for a robot, from a recording with ground
truth: the odometry's noise as Nav2's ``alpha1``…``alpha4`` (the odometry motion model fitted
over Nav2's update intervals) and the scanner's ``sigma_hit`` (the spread of the returns' end
points around the map at the true poses); printed as a Nav2 parameter block and as a ``tfloc
bench`` matcher entry (:mod:`tfloc.evaluation.motion_fit`).

Example:
  tfloc amcl-params --dataset data/scenarios/real-csail-native
"""

from __future__ import annotations

import argparse
from pathlib import Path

from tfloc.errors import DatasetError
from tfloc.evaluation.motion_fit import fit_motion_noise, fit_sigma_hit
from tfloc.io.scenario import SEQUENCE, map_for, read_scans, read_scenario

HELP = "measure AMCL's alpha1-4 and sigma_hit from a sequence with ground truth"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dataset", required=True, type=Path, help="a sequence dataset with truth on some rows")
    p.add_argument("--update-min-d", type=float, default=0.25, help="Nav2's update gate, metres (0.25)")
    p.add_argument("--update-min-a", type=float, default=0.2, help="... and radians (0.2)")
    p.add_argument("--hit-scans", type=int, default=200,
                   help="scans with truth used for sigma_hit, evenly spread (default 200; 0: all)")


def run(args: argparse.Namespace) -> int:
    scenario = read_scenario(args.dataset)
    if scenario.mode != SEQUENCE:
        raise DatasetError(f"{scenario.root}: not a sequence dataset (mode {scenario.mode!r})")
    scans = read_scans(scenario)
    try:
        fit = fit_motion_noise([s.odom for s in scans], [s.true for s in scans],
                               args.update_min_d, args.update_min_a)
    except ValueError as exc:
        raise DatasetError(f"{scenario.scans_path}: {exc}") from None
    truth = [s for s in scans if s.true is not None]
    if args.hit_scans and len(truth) > args.hit_scans:
        step = len(truth) / args.hit_scans
        truth = [truth[int(k * step)] for k in range(args.hit_scans)]
    sigma, n = fit_sigma_hit(map_for(scenario, scans[0], {}), scenario.laser,
                             [s.ranges for s in truth], [s.true for s in truth])
    print(f"# {scenario.name}: {fit.intervals} update intervals (mean {fit.mean_trans_m:.2f} m, "
          f"{fit.mean_turn_rad:.2f} rad; {fit.clipped} left out beyond 3 sigma), {n} end points "
          f"at {len(truth)} true poses")
    print("amcl:\n  ros__parameters:")
    for k in ("alpha1", "alpha2", "alpha3", "alpha4"):
        print(f"    {k}: {getattr(fit, k):.4f}")
    print(f"    sigma_hit: {sigma:.4f}")
    params = ", ".join(f"{k} = {getattr(fit, k):.4g}" for k in ("alpha1", "alpha2", "alpha3", "alpha4"))
    print(f'# tfloc bench: {{ label = "amcl-tuned", name = "amcl", params = {{ {params}, '
          f"sigma_hit = {sigma:.3g} }} }}")
    return 0
