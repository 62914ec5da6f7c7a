"""Run matchers over scenario datasets and write results/RUN/estimates.csv (resumable).

  tfloc bench DATASET_DIR... --matchers tf,o3d-icp --out results/RUN [--jobs N]
  tfloc bench benchmarks/NAME.toml [--jobs N] [--matchers ...]   (flags override the file)

A matcher is a registered name or LABEL=module:Class. Re-running the same command after an
interruption resumes: rows already in estimates.csv are not run again.
"""

from __future__ import annotations

import argparse
from pathlib import Path

HELP = "run matchers over scenario datasets (progress bar, time limits, resume)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("inputs", nargs="+", metavar="DATASET_DIR|CONFIG.toml")
    p.add_argument("--matchers", help="comma-separated matcher names (or LABEL=module:Class)")
    p.add_argument("--out", help="run directory (default results/<name>)")
    p.add_argument("--name", help="run name")
    p.add_argument("--jobs", type=int, help="worker processes (default 2)")
    p.add_argument("--timeout", type=float, dest="timeout_s", help="per-task time limit, s (default 120)")
    p.add_argument("--success-dist", type=float, dest="success_dist_m", help="success: distance error ≤ m (0.10)")
    p.add_argument("--success-orient", type=float, dest="success_orient_deg", help="success: orientation error ≤ deg (2)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--progress", action="store_true", default=None, help="force the progress bar")
    g.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")


def config_from_args(args: argparse.Namespace):
    from ..errors import ConfigError
    from ..harness.config import RunConfig, load_config

    tomls = [i for i in args.inputs if i.endswith(".toml")]
    matchers = tuple(m.strip() for m in args.matchers.split(",") if m.strip()) if args.matchers else None
    if tomls:
        if len(args.inputs) != 1:
            raise ConfigError("give either one CONFIG.toml or dataset directories, not both")
        cfg = load_config(tomls[0])
    else:
        if not matchers:
            raise ConfigError("--matchers is required without a CONFIG.toml")
        name = args.name or (Path(args.out).name if args.out else "run")
        cfg = RunConfig(name=name, out=args.out or f"results/{name}", datasets=tuple(args.inputs),
                        matchers=matchers)
    return cfg.with_overrides(matchers=matchers, out=args.out, name=args.name, jobs=args.jobs,
                              timeout_s=args.timeout_s, success_dist_m=args.success_dist_m,
                              success_orient_deg=args.success_orient_deg)


def run(args: argparse.Namespace) -> int:
    from ..harness.runner import run as run_bench

    cfg = config_from_args(args)
    path = run_bench(cfg, progress=args.progress)
    print(f"wrote {path}")
    return 0
