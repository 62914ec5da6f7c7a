"""Generate the bundled office maps and the scenario datasets of the paper's protocol.

Writes OUT/maps/office-{1,2,3}.geojson (rooms only, furnished, crowded),
OUT/scenarios/{office-pool,detail-1,detail-2,detail-3}, the simulated sequences
OUT/scenarios/seq-* (a robot driving routes through the three floors with odometry, under
labelled conditions: tfloc.datasets.sequences; the kidnapped sequences OUT/scenarios/seq-kidnap-*:
tfloc.datasets.kidnap) and the changed-world datasets
OUT/scenarios/changed-{clutter-0,clutter-10,clutter-25,furniture-gone} (the furnished office's
map, scans with unmapped people and boxes or without the furniture; tfloc.datasets.changed_world),
the second changed-world generator's OUT/scenarios/changed-{doors,moved,carts,months} (the crowded
office's map, scans after doors, movable objects, carts and people changed;
tfloc.datasets.rearranged), and the global-localization datasets OUT/scenarios/global-office-{1,2,3} (evaluation) and
global-dev-office-{1,2,3} (development; tfloc.datasets.global_sets). The same seeds give the
same bytes.
"""

from __future__ import annotations

import argparse

HELP = "generate the office maps and scenario datasets (reproducible from one seed)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    from tfloc.datasets.global_sets import GLOBAL_SEED, OFFICE_SCANS
    from tfloc.datasets.synthetic import MASTER_SEED

    p.add_argument("--out", default="data", help="output root (default: data)")
    p.add_argument("--seed", type=int, default=MASTER_SEED, help=f"master seed (default {MASTER_SEED})")
    p.add_argument("--per-cell", type=int, default=180,
                   help="office-pool scans per cell of the 3×3 grid (default 180 → 1620)")
    p.add_argument("--detail-per-cell", type=int, default=None,
                   help="detail-k scans per cell (default per-cell/3, i.e. 60 → 540)")
    p.add_argument("--sigma", type=float, default=0.01, help="Gaussian range noise σ, metres (0.01)")
    p.add_argument("--dropout", type=float, default=0.0, help="probability of a dropped return (0)")
    p.add_argument("--spurious", type=float, default=0.0, help="probability of a spurious short return (0)")
    p.add_argument("--clearance", type=float, default=0.3,
                   help="min distance of true and initial poses from geometry, metres (0.3)")
    p.add_argument("--no-sequences", action="store_true",
                   help="skip the sequence datasets seq-* (tracking)")
    p.add_argument("--global-seed", type=int, default=GLOBAL_SEED,
                   help=f"seed of the global-localization datasets (default {GLOBAL_SEED})")
    p.add_argument("--global-scans", type=int, default=OFFICE_SCANS,
                   help=f"scans per global-office-k dataset (default {OFFICE_SCANS})")


def run(args: argparse.Namespace) -> int:
    from tfloc.datasets.changed_world import generate_changed_world
    from tfloc.datasets.global_sets import generate_global_offices
    from tfloc.datasets.noise import NoiseModel
    from tfloc.datasets.rearranged import generate_rearranged
    from tfloc.datasets.synthetic import BundleSpec, generate_bundle

    detail = args.detail_per_cell if args.detail_per_cell is not None else max(1, args.per_cell // 3)
    spec = BundleSpec(seed=args.seed, pool_per_cell=args.per_cell, detail_per_cell=detail,
                      noise=NoiseModel(args.sigma, args.dropout, args.spurious),
                      clearance_m=args.clearance)
    generate_bundle(args.out, spec, log=print)
    if not args.no_sequences:
        from tfloc.datasets.sequences import SimSpec, generate_sequences

        generate_sequences(args.out, SimSpec(noise=spec.noise), log=print)
        from tfloc.datasets.kidnap import generate_kidnap_sequences

        generate_kidnap_sequences(args.out, SimSpec(noise=spec.noise), log=print)
    generate_changed_world(args.out, spec, log=print)
    generate_rearranged(args.out, spec, log=print)
    generate_global_offices(args.out, args.global_seed, args.global_scans, noise=spec.noise, log=print)
    return 0
