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
    """The robustness section of the run directory ``run`` (the study step ``robustness`` calls it)."""
    from tfloc.evaluation.metrics import prepare
    from tfloc.io.rundir import RunDir
    from tfloc.io.scenario import read_scenario
    from tfloc.report.robustness import (
        axes_of,
        paired_changes,
        robustness_cells,
        robustness_figure,
        robustness_markdown,
    )

    rd = RunDir(run)
    info = rd.info(required=True)
    scenarios = [read_scenario(d) for d in info.paths.values()]
    axes = axes_of((s.name, s.extra) for s in scenarios)
    prepared = prepare(rd.results(), info.thresholds)
    cells, changes = robustness_cells(prepared, axes), paired_changes(prepared, axes)
    fig = robustness_figure(cells, run / "figures" / "robustness.png") if figures else None
    out = run / "robustness.md"
    out.write_text(robustness_markdown(cells, changes, fig.relative_to(run).as_posix() if fig else None))
    cells.to_csv(run / "robustness.csv", index=False, float_format="%.4g")
    print(f"robustness: {out}", file=sys.stderr)
    return 0
