"""Write NOTE.md for a MIT CSAIL relations run: each matcher's relation errors (Kümmerle et al.
2009 style: mean ± std and max, absolute and squared), the odometry baseline, the published
figures and what can honestly be compared.
"""

from __future__ import annotations

import argparse
from pathlib import Path

HELP = "write the MIT CSAIL relations note (relation errors vs published figures) for a run"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("results", type=Path, help="run directory (with estimates.csv), e.g. results/real-csail-relations")
    parser.add_argument("--dataset", type=Path, action="append", dest="datasets",
                        help="a relations dataset, one per initial-guess protocol (repeatable; default: "
                             "data/scenarios/real-csail-relations and real-csail-relations-perturbed)")
    parser.add_argument("--max-dist-cm", type=float, default=10.0, help="success threshold (default 10 cm)")
    parser.add_argument("--max-angle-deg", type=float, default=2.0, help="success threshold (default 2°)")


def run(args: argparse.Namespace) -> int:
    from tfloc.evaluation.outcome import Thresholds
    from tfloc.report.relations_note import write_note

    datasets = args.datasets or [Path("data/scenarios/real-csail-relations"),
                                 Path("data/scenarios/real-csail-relations-perturbed")]
    print(write_note(args.results, datasets, Thresholds(args.max_dist_cm / 100.0, args.max_angle_deg)))
    return 0
