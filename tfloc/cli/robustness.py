"""Write the robustness section of a run: RUN/robustness.md and RUN/figures/robustness.png.

Success per matcher on every map style of the real logs and every changed world of the simulated
office (datasets with an "axis" in their scenario.json, e.g. benchmarks/robustness.toml), with
Wilson 95 % intervals, one table per log and the paired change against the as-built grid (real
logs) or the uncluttered world (simulation).

Example:
  tfloc robustness results/robustness
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HELP = "write RUN/robustness.md (success per map style and changed world) and its figure"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run", type=Path, metavar="RUN", help="run directory holding estimates.csv and run.json")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figure")


def run(args: argparse.Namespace) -> int:
    return robustness(args.run, figures=not args.no_figures)


def robustness(run: Path, figures: bool = True) -> int:
    """The robustness section of the run directory ``run`` (the study step ``robustness`` calls
    it): its tables derived (:func:`tfloc.harness.derive.derive_robustness`), then drawn."""
    from tfloc.harness.derive import derive_robustness
    from tfloc.report.robustness import robustness_figure, robustness_markdown

    cells, changes = derive_robustness(run)
    fig = robustness_figure(cells, run / "figures" / "robustness.png") if figures else None
    out = run / "robustness.md"
    out.write_text(robustness_markdown(cells, changes, fig.relative_to(run).as_posix() if fig else None))
    print(f"robustness: {out}", file=sys.stderr)
    return 0
