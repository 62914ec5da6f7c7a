"""Run registered matchers over scenario datasets and stream the results to RUN/estimates.csv.

Either name datasets and matchers on the command line, or give a run configuration (TOML,
see benchmarks/*.toml); options given on the command line override the file. Re-running the
same command after an interruption (Ctrl-C, kill -9) resumes: finished (scan, matcher) pairs
are skipped, nothing is repeated or lost. Each task has a time limit; a matcher that raises or
hangs gets an `error:`/`timeout` row and the run goes on.

--quick runs a small stratified subset (the first 3 scans of every group of every dataset) into
RUN-quick: a full report with figures in a few minutes (make quick).

Examples:
  tfloc bench benchmarks/paper-protocol.toml
  tfloc bench benchmarks/paper-protocol.toml --quick        # → results/paper-protocol-quick
  tfloc bench data/scenarios/detail-1 --matchers tf,csm-corr --out results/try --jobs 2
  tfloc bench benchmarks/paper-protocol.toml --scheduler tcp://HOST:8786   # on a Dask cluster
  tfloc bench benchmarks/paper-protocol.toml --scheduler local:2           # a local Dask cluster
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tfloc.core.matcher import available_matchers
from tfloc.errors import ConfigError
from tfloc.evaluation.outcome import Thresholds
from tfloc.harness.config import RunConfig, load_config, parse_matchers

HELP = "run matchers over scenario datasets (resumable), writing RUN/estimates.csv"
QUICK_PER_GROUP = 3


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("inputs", nargs="+", metavar="CONFIG.toml | DATASET_DIR",
                   help="a run configuration, or one or more scenario dataset directories")
    p.add_argument("--matchers", help="comma-separated matcher names (default with datasets: all "
                   f"registered: {','.join(available_matchers())})")
    p.add_argument("--out", type=Path, help="run directory (default: results/<name>)")
    p.add_argument("--name", help="run name (default: the config's, or 'run')")
    p.add_argument("--jobs", type=int, help="worker processes (default 2)")
    p.add_argument("--timeout", type=float, help="time limit per (scan, matcher) task, seconds (default 60)")
    p.add_argument("--limit-per-group", type=int,
                   help="only the first N scans of each group (smoke runs; default: all)")
    p.add_argument("--success-cm", type=float, help="success threshold on distance error, cm (default 10)")
    p.add_argument("--success-deg", type=float, help="success threshold on orientation error, degrees (default 2)")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT | local:N",
                   help="run the tasks on a Dask cluster: a running scheduler, or local:N for a "
                   "LocalCluster of N workers (needs: pip install tfloc[dask]; default: a local "
                   "process pool of --jobs workers)")
    p.add_argument("--quick", action="store_true",
                   help=f"a quick first run: the first {QUICK_PER_GROUP} scans of each group (unless "
                   "--limit-per-group says otherwise), into OUT-quick (unless --out is given)")
    p.add_argument("--regenerate", action="store_true",
                   help="if OUT holds a complete run, discard it and run again (an interrupted run "
                        "is still resumed); make bench uses this to reproduce the committed results")
    prog = p.add_mutually_exclusive_group()
    prog.add_argument("--progress", dest="progress", action="store_true", default=None,
                      help="always show the progress bar (default: only on a terminal)")
    prog.add_argument("--no-progress", dest="progress", action="store_false")


def config_from_args(args: argparse.Namespace) -> RunConfig:
    tomls = [i for i in args.inputs if i.endswith(".toml")]
    if tomls and len(args.inputs) > 1:
        raise ConfigError("give either one run configuration (.toml) or dataset directories, not both")
    if tomls:
        cfg = load_config(tomls[0])
        if args.matchers:
            cfg = cfg.with_overrides(matchers=parse_matchers(args.matchers.split(","), {}, "--matchers"))
    else:
        names = args.matchers.split(",") if args.matchers else available_matchers()
        name = args.name or "run"
        cfg = RunConfig(name=name, out=args.out or Path("results") / name,
                        datasets=tuple(Path(d) for d in args.inputs),
                        matchers=parse_matchers(names, {}, "--matchers"))
    if args.quick:
        cfg = cfg.with_overrides(name=f"{cfg.name}-quick", out=cfg.out.with_name(f"{cfg.out.name}-quick"),
                                 limit_per_group=QUICK_PER_GROUP)
    return cfg.with_overrides(
        name=args.name, out=args.out, jobs=args.jobs, timeout_s=args.timeout,
        limit_per_group=args.limit_per_group,
        success=None if args.success_cm is None and args.success_deg is None else Thresholds(
            cfg.success.dist_m if args.success_cm is None else args.success_cm / 100.0,
            cfg.success.orient_deg if args.success_deg is None else args.success_deg))


def run(args: argparse.Namespace) -> int:
    from tfloc.harness.runner import execute_local
    from tfloc.harness.runner import run as run_benchmark

    cfg = config_from_args(args)
    executor = execute_local
    if args.scheduler:
        from tfloc.harness.dask_executor import execute_dask

        executor = execute_dask(args.scheduler)
    out = run_benchmark(cfg, progress=args.progress, executor=executor, regenerate=args.regenerate)
    print(f"results: {out / 'estimates.csv'}  (report: tfloc report {out})", file=sys.stderr)
    return 0
