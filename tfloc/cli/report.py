"""Derive a run's tables from its rows, then draw its comparison report: RUN/headline.csv,
summary.csv, paired.csv (and, as the run's datasets call for, tracking.csv, kidnap.csv,
start.csv, selfassess.csv, relocalization.csv), then RUN/report.md and RUN/figures/*.png. The
tables are re-made from the rows, never by running a matcher; run.json records the code that
derived them.

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

HELP = "derive a run's tables (headline.csv, summary.csv, …) from its rows and draw RUN/report.md and RUN/figures/"


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


#: ``run.json``'s ``derived`` key of report.md, and the code that draws it
REPORT = "report"
REPORT_CODE = ("tfloc.report.report",)


def make_report(run: Path, thresholds=None, with_figures: bool = True):
    """The report of the run directory ``run`` (``thresholds``: a :class:`~tfloc.core.thresholds.Thresholds`
    to re-score with, default the run's): its tables derived from the rows
    (:func:`tfloc.harness.derive.derive`), ``tf``'s landscapes computed
    (:mod:`tfloc.harness.landscape`), each matcher's code checked against this checkout's, then
    drawn (:func:`tfloc.report.report.write_report`) and recorded; returns what was written."""
    from tfloc.core.run import DerivedRecord
    from tfloc.evaluation.summary import declaring
    from tfloc.harness.derive import derive
    from tfloc.harness.identity import derived_code, stale_matchers
    from tfloc.harness.landscape import landscapes
    from tfloc.io.rundir import RunDir
    from tfloc.report.report import write_report

    run = Path(run)
    d = derive(run, thresholds)
    single = d.prepared[~d.prepared["dataset"].isin(d.sequences | d.globals_)]
    panels = []
    if with_figures and len(single):
        paper = d.record.paper_scenarios()
        binned = sorted(set(declaring(paper, "II")) | set(declaring(paper, "III")))
        panels = landscapes(single, d.record.paths, binned)
    files = write_report(run, thresholds, headline=d.headline, note=d.truth_free.note, landscapes=panels,
                         stale_code=stale_matchers(d.record.fingerprint), with_figures=with_figures)
    rd = RunDir(run)
    rd.record_derived(REPORT, DerivedRecord(derived_code(*REPORT_CODE), rd.rows_sha256()))
    return files


def report(run: Path, thresholds=None, figures: bool = True) -> int:
    """The verb on the run directory ``run`` (:func:`make_report`), with where it wrote (the
    study step ``report`` calls it)."""
    files = make_report(run, thresholds, with_figures=figures)
    print(f"report: {files.report}", file=sys.stderr)
    if files.figures:
        print(f"figures: {len(files.figures)} in {files.figures[0].parent}", file=sys.stderr)
    return 0
