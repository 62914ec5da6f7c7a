"""Run a study: matchers over scenario datasets, results streamed to RUN/estimates.csv, then the
steps that make its tables.

Either name datasets and matchers on the command line, or give study files (benchmarks/*.toml:
each one run, then the steps it declares, e.g. steps = ["timing", "report"]; a file may extend
another, extends = "robustness.toml"); options given on the command line override a single
file. Every matcher is built before anything runs: a bad parameter stops the command at once.
Re-running the same command after an interruption (Ctrl-C, kill -9) resumes it. A run directory
holds one configuration (run.json's fingerprint); another is refused there: use --regenerate or
another --out. Every task ends in one row: ok, failed, invalid:<reason>, timeout or error:<message>
(docs/running.md, "A run is one configuration").

Exit status: 0 the run is complete (rows may be failed, invalid or timeout); 2 nothing was run
(a bad configuration, dataset or parameter, a run of another configuration in --out, an output
that cannot be written); 3 the run is complete but some task raised an error (a matcher bug: see
the `error:` rows; --retry-errors runs them again).

Matchers named `module:Class` are imported (their code runs): refused without --allow-import.
A sequence dataset without truth named directly is then judged (tfloc verdict) and reported.

--quick runs the first 3 scans of every group of every dataset into RUN-quick (make quick).

Examples:
  tfloc bench benchmarks/paper-protocol.toml   # the run, its timing pass and its report
  tfloc bench benchmarks/robustness.toml benchmarks/global.toml --regenerate
  tfloc bench benchmarks/paper-protocol.toml --quick   # → results/paper-protocol-quick
  tfloc bench data/scenarios/detail-1 --matchers tf,csm-corr --out results/try
  tfloc bench benchmarks/paper-protocol.toml --scheduler local:2   # a local Dask cluster
  tfloc bench benchmarks/paper-protocol.toml --scheduler tls://HOST:8786 \\
      --tls-ca-file ca.pem --tls-cert client.pem --tls-key client.key   # a Dask cluster over TLS
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

from tfloc.core.matcher import default_matchers
from tfloc.core.thresholds import Thresholds
from tfloc.errors import ConfigError
from tfloc.harness.config import (
    STEPS_BEFORE,
    RunConfig,
    Study,
    check_imports,
    load_study,
    parse_matchers,
)
from tfloc.io.scenario import read_scenario
from tfloc.site.pages import quick_name

from ._options import add_progress

HELP = "run matchers over scenario datasets (resumable), writing RUN/estimates.csv"
QUICK_PER_GROUP = 3


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("inputs", nargs="+", metavar="STUDY.toml | DATASET_DIR",
                   help="one or more study files (run one after the other, each followed by its steps), "
                        "or one or more scenario dataset directories")
    p.add_argument("--matchers", help="comma-separated matcher names or presets (default with datasets: "
                   "every registered matcher that solves their mode: the single-scan matchers on a "
                   "single-scan dataset, trackers and single-scan matchers on a sequence, the global "
                   "matchers on a global set; 'tfloc matchers' lists them)")
    p.add_argument("--datasets", metavar="NAMES",
                   help="with a run configuration: only its datasets of these directory names "
                        "(comma-separated; a fixed subsample, e.g. make bench's native run)")
    p.add_argument("--out", type=Path, help="run directory (default: results/<name>)")
    p.add_argument("--name", help="run name (default: the config's, or 'run')")
    p.add_argument("--jobs", type=int, help="worker processes (default 2)")
    p.add_argument("--timeout", type=float, help="time limit per (scan, matcher) task, seconds (default 60)")
    p.add_argument("--limit-per-group", type=int,
                   help="only the first N scans of each group (smoke runs; default: all)")
    p.add_argument("--success-cm", type=float, help="success threshold on distance error, cm (default 10)")
    p.add_argument("--success-deg", type=float, help="success threshold on orientation error, degrees (default 2)")
    p.add_argument("--scheduler", metavar="tls://HOST:PORT | local:N",
                   help="run the tasks on a Dask cluster: a running scheduler, or local:N for a "
                   "LocalCluster of N workers on this machine (needs: pip install tfloc[dask]; default: "
                   "a local process pool of --jobs workers). Anyone who can reach a scheduler can run "
                   "code on its workers: use tls:// (or tcp:// through an SSH tunnel), never plain "
                   "tcp:// on a shared network")
    p.add_argument("--tls-ca-file", metavar="PEM", help="TLS: the certificate authority that signed the "
                   "scheduler's and workers' certificates (default: the Dask config, distributed.comm.tls)")
    p.add_argument("--tls-cert", metavar="PEM", help="TLS: this client's certificate")
    p.add_argument("--tls-key", metavar="PEM", help="TLS: this client's private key (if not in --tls-cert)")
    p.add_argument("--quick", action="store_true",
                   help=f"a quick first run: the first {QUICK_PER_GROUP} scans of each group (unless "
                   "--limit-per-group says otherwise), into OUT-quick (unless --out is given, or OUT ends in -quick)")
    p.add_argument("--regenerate", action="store_true",
                   help="if OUT holds a complete run, or a run of another configuration, discard it and "
                        "run again (an interrupted run of the same configuration is still resumed); make "
                        "bench uses this to reproduce the committed results")
    p.add_argument("--retry-errors", action="store_true",
                   help="run the tasks whose rows have status error:… or timeout again (their rows are "
                        "replaced)")
    p.add_argument("--allow-import", action="store_true",
                   help="allow matchers named module:Class: they are imported, which runs the module's "
                        "code; only for configurations you trust")
    p.add_argument("--no-steps", action="store_true",
                   help="run the study's run only, not the steps its file declares (steps = [...]: "
                        "index before the run; timing, report, robustness, real-note after it)")
    add_progress(p)


def only_datasets(cfg: RunConfig, names: list[str]) -> RunConfig:
    """``cfg`` with only its datasets whose directory name is one of ``names`` (in its order)."""
    names = [n.strip() for n in names if n.strip()]
    unknown = sorted(set(names) - {d.name for d in cfg.datasets})
    if unknown:
        raise ConfigError(f"--datasets: {', '.join(unknown)} not in run {cfg.name!r} "
                          f"(its datasets: {', '.join(d.name for d in cfg.datasets)})")
    keep = tuple(d for d in cfg.datasets if d.name in names)
    return replace(cfg, datasets=keep,
                   skip_per_group=tuple((k, n) for k, n in cfg.skip_per_group if Path(k) in keep))


def _overridden(args: argparse.Namespace) -> list[str]:
    """The options that change one run's configuration (they apply to one study file only)."""
    return [o for o, v in (("--matchers", args.matchers), ("--datasets", args.datasets), ("--out", args.out),
                           ("--name", args.name)) if v]


def config_from_args(args: argparse.Namespace, study: Study | None = None) -> RunConfig:
    """The run of one study file (``study``) or of the dataset directories given, with the
    command line's options on top."""
    tomls = [i for i in args.inputs if i.endswith(".toml")]
    if tomls and len(tomls) < len(args.inputs):
        raise ConfigError("give either study files (.toml) or dataset directories, not both")
    if tomls:
        study = study or load_study(tomls[0])
        if study.run is None:
            raise ConfigError(f"{study.path}: a {study.kind} study has no run configuration")
        cfg = study.run
        if args.matchers:
            cfg = cfg.with_overrides(matchers=parse_matchers(args.matchers.split(","), {}, "--matchers"))
        if args.datasets:
            cfg = only_datasets(cfg, args.datasets.split(","))
    elif args.datasets:
        raise ConfigError("--datasets selects datasets of a run configuration; give dataset directories directly")
    else:
        names = args.matchers.split(",") if args.matchers else default_matchers(
            {read_scenario(d).mode for d in args.inputs})
        name = args.name or "run"
        cfg = RunConfig(name=name, out=args.out or Path("results") / name,
                        datasets=tuple(Path(d) for d in args.inputs),
                        matchers=parse_matchers(names, {}, "--matchers"), steps=())
    if args.quick:
        cfg = cfg.with_overrides(name=quick_name(cfg.name), out=cfg.out.with_name(quick_name(cfg.out.name)),
                                 limit_per_group=QUICK_PER_GROUP)
    return cfg.with_overrides(
        name=args.name, out=args.out, jobs=args.jobs, timeout_s=args.timeout,
        limit_per_group=args.limit_per_group,
        success=None if args.success_cm is None and args.success_deg is None else Thresholds(
            cfg.success.dist_m if args.success_cm is None else args.success_cm / 100.0,
            cfg.success.orient_deg if args.success_deg is None else args.success_deg))


def run(args: argparse.Namespace) -> int:
    from ._study import run_scaling_study, run_steps

    tomls = [i for i in args.inputs if i.endswith(".toml")]
    if len(tomls) > 1 and _overridden(args):
        raise ConfigError(f"{', '.join(_overridden(args))}: apply to one study file, not {len(tomls)}")
    if not tomls:
        cfg = config_from_args(args)
        code = run_one(args, cfg)
        if not args.no_steps and code in (0, 3) and _without_truth(cfg):
            run_steps(cfg, ["verdict", "report"], args.quick)
        return code
    studies = [load_study(t) for t in tomls]  # every file checked before any runs
    code = 0
    for study in studies:
        if study.kind == "scaling":
            code = max(code, run_scaling_study(study, args))
            continue
        cfg = config_from_args(args, study)
        if not args.no_steps:
            run_steps(cfg, [s for s in cfg.steps if s in STEPS_BEFORE], args.quick)
        code = max(code, run_one(args, cfg))
        if not args.no_steps:
            run_steps(cfg, [s for s in cfg.steps if s not in STEPS_BEFORE], args.quick)
    return code


def _without_truth(cfg: RunConfig) -> bool:
    """Whether a run has a sequence dataset without truth: then ``tfloc bench DATASET …`` judges
    it (``tfloc verdict``) and writes its report, which opens with the truth-free ranking."""
    from tfloc.io.scenario import SEQUENCE

    return any((sc := read_scenario(d)).mode == SEQUENCE and not sc.has_truth for d in cfg.datasets)


def run_one(args: argparse.Namespace, cfg: RunConfig) -> int:
    """One run (resumed, or refused if ``--out`` holds another configuration); 3 if a task raised."""
    from tfloc.harness.runner import execute_local
    from tfloc.harness.runner import run as run_benchmark
    from tfloc.io.estimates import status_counts
    from tfloc.io.rundir import RunDir

    check_imports(cfg, args.allow_import)
    tls = {k: getattr(args, k) for k in ("tls_ca_file", "tls_cert", "tls_key") if getattr(args, k)}
    if tls and not args.scheduler:
        raise ConfigError("--tls-ca-file/--tls-cert/--tls-key apply to --scheduler tls://… only")
    executor = execute_local
    if args.scheduler:
        from tfloc.harness.dask_executor import execute_dask, security

        executor = execute_dask(args.scheduler, security(args.scheduler, **tls))
    out = run_benchmark(cfg, progress=args.progress, executor=executor, regenerate=args.regenerate,
                        retry_errors=args.retry_errors)
    rows = RunDir(out).estimates
    counts = status_counts(rows)
    print(f"rows: {sum(counts.values())} (" + ", ".join(f"{k} {n}" for k, n in counts.items()) + ")",
          file=sys.stderr)
    print(f"results: {rows}  (report: tfloc report {out})", file=sys.stderr)
    if counts["error"]:
        print(f"tfloc bench: {counts['error']} task(s) raised an error (see the error: rows); after a fix, "
              "rerun them with --retry-errors", file=sys.stderr)
        return 3
    return 0
