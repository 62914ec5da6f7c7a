"""Re-time a run's matchers side by side on a stratified sample of its scans: RUN/timing.csv, RUN/timing.md.

One process pinned to the given cores, every library on one thread, a warm-up, then scan by
scan every matcher once (order rotated per scan), timed by CPU time (wall time beside it).
timing.md gives the median CPU ms per matcher with bootstrap intervals, the ratio to a
reference matcher, and the run's own CPU times on the same scans (see tfloc.harness.timing).
make bench runs it after the accuracy runs; tfloc report links timing.md when present.

Examples:
  tfloc timing results/paper-protocol
  tfloc timing results/paper-protocol --per-stratum 10 --cores 1 --reference o3d-icp
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HELP = "re-time a run's matchers side by side on a stratified sample of its scans (timing.md)"


def _cores(text: str) -> list[int]:
    try:
        return [int(c) for c in text.split(",") if c.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"cores must be comma-separated integers, got {text!r}") from None


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("run", type=Path, metavar="RUN", help="run directory (estimates.csv, run.json)")
    p.add_argument("--per-stratum", type=int, default=4,
                   help="scans per dataset × group (default 4)")
    p.add_argument("--seed", type=int, default=None, help="sampling seed (default: fixed)")
    p.add_argument("--cores", type=_cores, default=None,
                   help="comma-separated cores to pin the process to (default: the last allowed core)")
    p.add_argument("--reference", default=None, help="reference matcher of the ratios (default: tf-plus, "
                   "else the first)")
    p.add_argument("--warmup", type=int, default=2, help="untimed localize calls per dataset and matcher (default 2)")


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from tfloc.errors import ConfigError
    from tfloc.evaluation.timing import reference_of, timing_summary
    from tfloc.harness.timing import SEED, read_run, run_timing
    from tfloc.report.timing import write_timing

    df, run_info = read_run(args.run)
    try:
        reference = reference_of([m["label"] for m in run_info.matchers], args.reference)
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    bar = tqdm(unit="scan", desc="timing", disable=not sys.stderr.isatty())

    def progress(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.n)

    rows, info = run_timing(args.run, args.per_stratum, SEED if args.seed is None else args.seed, args.cores,
                            args.warmup, progress, run=(df, run_info))
    bar.close()
    summary = timing_summary(rows, reference, df)
    csv_path, md_path = write_timing(args.run, rows, summary, reference, info,
                                     run_info.name or args.run.name)
    print(summary[["matcher", "cpu_median_ms", "ratio_to_reference", "run_over_quiet"]].to_string(
        index=False, float_format=lambda v: f"{v:.2f}"), file=sys.stderr)
    print(f"timing: {md_path} ({csv_path.name})", file=sys.stderr)
    return 0
