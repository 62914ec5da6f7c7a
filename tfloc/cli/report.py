"""Write a run's comparison report: RUN/report.md, RUN/summary.csv and RUN/figures/*.png.

The report puts the paper's published Tables 2–4 next to the measured tf values, then the same
tables for every matcher of the run, per-dataset accuracy / success / outcome / runtime tables
and figures (errors per scenario, convergence basin, error CDF, runtime, outcomes). Success
thresholds default to those the run was made with (run.json); --success-cm/--success-deg
re-score the run without re-running it.

Examples:
  tfloc report results/paper-protocol
  tfloc report results/try --success-cm 5 --success-deg 1 --no-figures
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HELP = "write RUN/report.md, RUN/summary.csv and RUN/figures/ from a run's estimates.csv"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run", type=Path, metavar="RUN", help="run directory holding estimates.csv and run.json")
    p.add_argument("--success-cm", type=float, help="success threshold on distance error, cm (default: the run's)")
    p.add_argument("--success-deg", type=float,
                   help="success threshold on orientation error, degrees (default: the run's)")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")


def run(args: argparse.Namespace) -> int:
    from tfloc.core.thresholds import Thresholds
    from tfloc.io.rundir import RunDir

    thr = None
    if args.success_cm is not None or args.success_deg is not None:
        base = RunDir(args.run).info().thresholds
        thr = Thresholds(base.dist_m if args.success_cm is None else args.success_cm / 100.0,
                         base.orient_deg if args.success_deg is None else args.success_deg)
    return report(args.run, thr, figures=not args.no_figures)


def report(run: Path, thresholds=None, figures: bool = True) -> int:
    """The report of the run directory ``run`` (``thresholds``: a :class:`~tfloc.core.thresholds.Thresholds`
    to re-score with, default the run's), with where it wrote (the study step ``report`` calls it)."""
    from tfloc.report.report import write_report

    files = write_report(run, thresholds, with_figures=figures)
    print(f"report: {files.report}\nsummary: {files.summary}", file=sys.stderr)
    if files.figures:
        print(f"figures: {len(files.figures)} in {files.figures[0].parent}", file=sys.stderr)
    return 0
