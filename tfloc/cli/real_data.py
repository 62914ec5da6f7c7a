"""Build the real-data scenario datasets from the logs in data/real/ (deterministic for a seed).

Writes OUT/scenarios/real-csail-relations/ and real-csail-relations-perturbed/ (scan-to-scan, the
1172 MIT CSAIL relations from the odometry guess and from perturbed guesses),
OUT/scenarios/real-{intel,csail,aces}-scan-to-map/ (scan-to-map), their grid maps
OUT/maps/real-{intel,csail,aces}.yaml|.pgm, OUT/scenarios/real-{intel,csail,aces}-sequence/
(tracking, condition real-sparse: every corrected scan in time order, odometry simulated from the
corrected increments), OUT/scenarios/real-{intel,csail,aces}-native/ (tracking, condition
real-native: every raw scan from the first corrected one on, the robot's raw odometry, truth on the
corrected scans; tfloc.datasets.real_native), and the map-style datasets
OUT/scenarios/real-{intel,csail,aces}-<style>/ with their maps OUT/maps/styles/ (every 4th scan of
each log on the same corrected scans drawn as other mapping tools draw them: as-built, hits-only,
thick-1, thick-2, cartographer, gmapping, incomplete; tfloc.datasets.styles), and the
global-localization datasets OUT/scenarios/real-{intel,csail,aces}-global/ (evaluation) and global-dev-real-*/ (development;
tfloc.datasets.global_sets).
"""

from __future__ import annotations

import argparse
from pathlib import Path

HELP = ("build the real-log scenario datasets (MIT CSAIL relations, Intel/CSAIL/ACES scan-to-map, "
        "sparse and native-rate sequences, map styles and global sets)")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from tfloc.datasets.real import DEFAULT_SEED

    parser.add_argument("--real", type=Path, default=Path("data/real"),
                        help="directory with the logs (default: data/real)")
    parser.add_argument("--out", type=Path, default=Path("data"),
                        help="data directory to write scenarios/ and maps/ into (default: data)")
    parser.add_argument("--seed", type=int, default=DEFAULT_SEED,
                        help=f"seed of the initial-pose perturbations (default: {DEFAULT_SEED})")
    parser.add_argument("--resolution", type=float, default=0.05,
                        help="grid map cell size in metres (default: 0.05)")


def run(args: argparse.Namespace) -> int:
    from tfloc.datasets.global_sets import build_global_real
    from tfloc.datasets.real import build_all
    from tfloc.datasets.real_native import build_native
    from tfloc.datasets.real_sequences import build_sequences
    from tfloc.datasets.relations import build_relations
    from tfloc.datasets.styles import build_styles

    for root in [*build_relations(args.real, args.out, args.seed),
                 *build_all(args.real, args.out, args.seed, args.resolution),
                 *build_sequences(args.real, args.out),
                 *build_native(args.real, args.out),
                 *build_styles(args.real, args.out, args.seed, args.resolution),
                 *build_global_real(args.real, args.out)]:
        print(root)
    return 0
