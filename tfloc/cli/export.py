"""Export a run's poses for other tools: per dataset, TUM trajectory files of the reference
(true) poses, the initial guesses and each matcher's estimates (timestamp x y z qx qy qz qw).

Timestamps are the scans' stamps (datasets made by 'tfloc import-bag' carry them), else the
scan's row index in the dataset. evo reads the files unchanged, for example:
  tfloc export results/run1 --tum tum/
  evo_ape tum tum/run1/reference.tum tum/run1/tf.tum --plot
"""

from __future__ import annotations

import argparse
from pathlib import Path

HELP = "export a run's estimated, initial and reference poses as TUM trajectory files (for evo)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run", type=Path, help="run directory holding estimates.csv (or a name under results/)")
    p.add_argument("--tum", type=Path, required=True, metavar="DIR",
                   help="write DIR/<dataset>/{reference,initial,<matcher>}.tum")
    p.add_argument("--datasets", type=Path, default=Path("data/scenarios"),
                   help="where to look for the datasets named in the run (default: data/scenarios)")


def run(args: argparse.Namespace) -> int:
    from tfloc.harness.export import export_tum
    from tfloc.io.rundir import RunDir

    run_dir = args.run
    if not RunDir(run_dir).has_rows() and RunDir(Path("results") / run_dir).has_rows():
        run_dir = Path("results") / run_dir
    for e in export_tum(run_dir, args.tum, args.datasets):
        where = e.path if e.path is not None else "(nothing written)"
        note = f", {e.missing} without a pose" if e.missing else ""
        print(f"{e.dataset} {e.role}: {e.poses} poses{note} (times: {e.stamps}) → {where}")
    return 0
