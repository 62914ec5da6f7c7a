"""Accuracy regression guard: rerun the fixed-seed subset (benchmarks/regression.toml) and compare
its metrics with the committed reference (results/reference/summary.csv).

Exits 1 and prints a table of every metric that got worse than its tolerance allows
(tolerances and their justification: tfloc/evaluation/guard.py). With --update, rewrites the
reference deliberately and prints what changed.

Examples:
  tfloc guard   # check
  tfloc guard --update   # accept the current results as the new reference
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from tfloc.errors import ConfigError

if TYPE_CHECKING:
    import pandas as pd

    from tfloc.harness.config import RunConfig

HELP = "accuracy regression guard: rerun a fixed subset and compare with the reference"
CONFIG = Path("benchmarks/regression.toml")
REFERENCE = Path("results/reference/summary.csv")
TRACKING_CONFIG = Path("benchmarks/regression-tracking.toml")
TRACKING_REFERENCE = Path("results/reference/tracking.csv")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--config", type=Path, default=CONFIG, help=f"subset run configuration ({CONFIG})")
    p.add_argument("--reference", type=Path, default=REFERENCE, help=f"reference metrics ({REFERENCE})")
    p.add_argument("--tracking-config", type=Path, default=TRACKING_CONFIG,
                   help=f"the tracking guard's sequence run ({TRACKING_CONFIG})")
    p.add_argument("--tracking-reference", type=Path, default=TRACKING_REFERENCE,
                   help=f"the tracking guard's reference ({TRACKING_REFERENCE})")
    p.add_argument("--no-tracking", action="store_true", help="only the single-scan guard")
    p.add_argument("--update", action="store_true", help="rewrite the reference with this run's metrics")
    p.add_argument("--matchers", help="only these matchers (comma-separated)")
    p.add_argument("--jobs", type=int, help="worker processes (default from the config)")
    p.add_argument("--resume", action="store_true", help="reuse a previous guard run's finished rows")
    p.add_argument("--all", action="store_true", help="print every compared metric, not only regressions")


def run(args: argparse.Namespace) -> int:
    from tfloc.evaluation import guard
    from tfloc.io.tables import GUARD, GUARD_TRACKING

    parts = [(args.config, args.reference, guard.guard_summary, guard.RULES, GUARD)]
    if not args.no_tracking and args.tracking_config.exists():
        parts.append((args.tracking_config, args.tracking_reference, guard.tracking_summary, guard.TRACK_RULES,
                      GUARD_TRACKING))
    worse = 0
    for config, reference, summarise, rules, table in parts:
        status = _one(args, config, reference, summarise, rules, table)
        if status is None:
            continue
        worse += status
    return 1 if worse else 0


def _one(args: argparse.Namespace, config: Path, reference: Path, summarise, rules, table) -> int | None:
    """One guard (a subset and its reference, a file of ``table``): None after ``--update``,
    else the number of metrics worse than the reference allows."""
    import pandas as pd

    from tfloc.evaluation import guard
    from tfloc.harness.config import load_config, parse_matchers
    from tfloc.io.rundir import RunDir
    from tfloc.io.table import read_frame, write

    cfg = load_config(config)
    if args.matchers:
        cfg = cfg.with_overrides(matchers=parse_matchers(args.matchers.split(","), {}, "--matchers"))
    cfg = cfg.with_overrides(jobs=args.jobs)
    current = run_subset(cfg, fresh=not args.resume, summarise=summarise)
    if args.update:
        old = read_frame(reference, table)
        if args.matchers and reference.exists():  # keep the other matchers' reference rows
            keep = old[~old.matcher.isin(current.matcher.unique())]
            current = pd.concat([keep, current]).sort_values(list(guard.KEY), ignore_index=True)
        write(reference, table, current)
        record = reference.with_suffix(".run.json")  # the code and configuration that made it
        shutil.copyfile(RunDir(cfg.out).run_json, record)
        print(f"updated {reference} (made as {record} records):\n{guard.format_changes(old, current)}")
        return None
    if not reference.exists():
        raise ConfigError(f"{reference}: no reference yet; create it with 'tfloc guard --update'")
    diff = guard.compare(current, read_frame(reference, table), rules)
    print(guard.format_table(diff, only_worse=not args.all))
    n = int(diff.worse.sum())
    if n:
        print(f"\n{config}: {n} metric(s) worse than the reference allows", file=sys.stderr)
    else:
        print(f"\n{config}: all {len(diff)} guarded metrics within tolerance", file=sys.stderr)
    return n


def run_subset(config: RunConfig, fresh: bool = True, progress: bool | None = None,
               summarise=None) -> pd.DataFrame:
    """Run the guard's subset (from scratch unless ``fresh`` is False) and summarise it
    (``summarise``: :func:`tfloc.evaluation.guard.guard_summary` by default)."""
    from tfloc.evaluation.guard import guard_summary
    from tfloc.harness.runner import run as run_benchmark
    from tfloc.io.rundir import RunDir

    if fresh and Path(config.out).exists():
        shutil.rmtree(config.out)
    out = run_benchmark(config, progress=progress)
    return (summarise or guard_summary)(RunDir(out).results(), config.success)
