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
    parser.add_argument("--max-dist-cm", type=float, help="success threshold on distance, cm (default: the run's)")
    parser.add_argument("--max-angle-deg", type=float, help="success threshold on orientation, degrees (default: the run's)")


def run(args: argparse.Namespace) -> int:
    return note(args.results, args.datasets, args.max_dist_cm, args.max_angle_deg)


def note(results: Path, datasets: list[Path] | None = None, max_dist_cm: float | None = None,
         max_angle_deg: float | None = None) -> int:
    """The relations note of the run directory ``results`` (thresholds default to the run's; the
    study step ``real-note`` calls it)."""
    from tfloc.core.thresholds import Thresholds
    from tfloc.io.rundir import RunDir
    from tfloc.report.relations_note import write_note

    datasets = datasets or [Path("data/scenarios/real-csail-relations"),
                            Path("data/scenarios/real-csail-relations-perturbed")]
    run = RunDir(results).info().thresholds
    thr = Thresholds(run.dist_m if max_dist_cm is None else max_dist_cm / 100.0,
                     run.orient_deg if max_angle_deg is None else max_angle_deg)
    print(write_note(results, datasets, thr))
    return 0
