"""Judge a run's trackers without the truth: RUN/verdict.csv and the per-scan signals beside it.

For every sequence dataset of the run, each tracker's answers are judged from what a robot owner
has: the scans, the map, the odometry and the other trackers' answers, never the truth. Signals
per scan: the share of returns that land on the map, agreement with the pose independent other
trackers agree on, corrections beyond the odometry's measured noise (jumps), and restarts from
perturbed poses that come back to the tracker's own trajectory. The verdict is the share of
scans each tracker is believed tracked, with a 95 % interval (docs/truth-free.md).
Where a dataset has truth, the verdict is then checked against it (verdict_agreement.csv:
rank correlation, top tracker, the scans judged wrongly). tfloc report opens with the verdict
for datasets without truth; tfloc bench on such a dataset runs this step itself.

Examples:
  tfloc verdict results/my-robot
  tfloc verdict results/native --no-restarts   # the signals from the rows alone (no tracker runs)
  tfloc verdict results/dev/truth-free --sweep fit_margin=0.05,0.2 --sweep min_methods=1,3
      # other values of the verdict's rules, each checked against the truth (verdict_sweep.csv)
"""

from __future__ import annotations

import argparse
from pathlib import Path

HELP = "judge a run's trackers without ground truth (the truth-free verdict: verdict.csv)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run", type=Path, metavar="RUN", help="run directory (estimates.csv, run.json)")
    p.add_argument("--no-restarts", action="store_true",
                   help="skip the re-convergence restarts (they run every tracker again on a few stretches)")
    p.add_argument("--sweep", action="append", default=[], metavar="KEY=V1,V2",
                   help="also judge with other values of one rule (tfloc.evaluation.truthfree.config), "
                        "each checked against the truth: RUN/verdict_sweep.csv (repeatable; no restarts)")


def run(args: argparse.Namespace) -> int:
    from tfloc.harness.verdict_sweep import parse_sweep, sweep
    from tfloc.io.rundir import RunDir
    from tfloc.io.tables import VERDICT_SWEEP

    if args.sweep:
        configs = parse_sweep(args.sweep)
        sweep(args.run, configs)
        print(f"sweep: {RunDir(args.run).file(VERDICT_SWEEP)} ({len(configs)} configurations)")
        return 0
    return judge(args.run, restarts=not args.no_restarts)


def judge(run: Path, restarts: bool = True) -> int:
    """The verdict of the run directory ``run``, written, with one line per recording against
    the truth (the study step ``verdict`` calls it)."""
    from tfloc.harness.verdict import write_verdict
    from tfloc.io.rundir import RunDir
    from tfloc.io.tables import VERDICT

    v = write_verdict(run, restarts=restarts)
    print(f"verdict: {RunDir(run).file(VERDICT)} ({len(v.rows)} rows)")
    for a in v.agreements:
        print(f"{a.dataset}: against the truth rho {a.rho:.2f}, top {a.verdict_top} ({a.top}; truth's "
              f"{a.truth_top}){'' if a.agrees else ': DISAGREES'}")
    return 0
