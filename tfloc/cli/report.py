"""Write report.md, summary.csv and figures/*.png for a benchmark run directory."""

from __future__ import annotations

import argparse

HELP = "summarise a run: report.md (paper's Tables 2-4), summary.csv, figures"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run", metavar="RUN", help="run directory (holds estimates.csv)")


def run(args: argparse.Namespace) -> int:
    from ..harness.report import write_report

    print(f"wrote {write_report(args.run)}")
    return 0
