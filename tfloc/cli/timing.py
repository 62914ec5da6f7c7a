"""Re-time a run's matchers side by side on a stratified sample of its scans: RUN/timing.csv, RUN/timing.md.

One process pinned to the given cores, every library on one thread, a warm-up, then scan by
scan every matcher once (order rotated per scan), timed by CPU time (wall time beside it).
timing.md gives the median CPU ms per matcher with bootstrap intervals, the ratio to a
reference matcher, and the run's own CPU times on the same scans (see tfloc.harness.timing).
make bench runs it after the accuracy runs; tfloc report links timing.md when present.

RUN/run.json records the pass (its fingerprint: the run's, --per-stratum, --seed, --warmup,
--reference, the sample and the code timed; its sessions). Run again on a run whose pass is
complete and current, it says so and times nothing; a pass of other options, a run whose rows
or code changed, or an interrupted pass is timed again; --regenerate always times again.

A contention probe (a fixed calibration workload timed before each scan's matchers, and the
machine's busy time) says whether the pass ran contended (tfloc.evaluation.contention): such a
pass is timed again after --wait seconds, --retries times, then refused (exit 2, nothing
written); with --allow-contended it is written at once and marked contended in timing.md, the
site and run.json. --verify re-times the committed pass's scans now (--per-stratum N: the first N
of each stratum), writes nothing, prints the ratio now / committed per matcher and exits 1 if any
lies outside ×1.3; a re-timing whose calibration runs outside ×1.25 of the committed pass's
speed (the machine itself slower or faster) is retried and refused as a contended one is. On
another CPU model than the committed pass's (its record's, else the run's machine's) absolute
CPU times do not compare: --verify says so in one line and compares each matcher's ratio to the
reference matcher, timed side by side, now with the committed one (exit 1 outside ×1.3), with
no machine-speed check; contention the re-timing's own probe finds is still retried and refused.

Examples:
  tfloc timing results/paper-protocol
  tfloc timing results/paper-protocol --per-stratum 10 --cores 1 --reference o3d-icp
  tfloc timing results/paper-protocol --verify
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
    p.add_argument("--per-stratum", type=int, default=None,
                   help="scans per dataset × group (default 4)")
    p.add_argument("--seed", type=int, default=None, help="sampling seed (default: fixed)")
    p.add_argument("--cores", type=_cores, default=None,
                   help="comma-separated cores to pin the process to (default: the last allowed core)")
    p.add_argument("--reference", default=None, help="reference matcher of the ratios (default: tf-plus, "
                   "else the first)")
    p.add_argument("--warmup", type=int, default=None, help="untimed localize calls per dataset and matcher (default 2)")
    p.add_argument("--regenerate", action="store_true",
                   help="time again even if the run's timing pass is complete and current")
    p.add_argument("--allow-contended", action="store_true",
                   help="keep a pass the contention probe finds contended (marked so) instead of retrying and refusing it")
    p.add_argument("--retries", type=int, default=None, help="times a contended pass is timed again before "
                   "it is refused (default 2)")
    p.add_argument("--wait", type=float, default=None, help="seconds before each of those tries (default 60)")
    p.add_argument("--verify", action="store_true", help="re-time the committed pass's scans now and "
                   "compare (exit 1 if a matcher's ratio lies outside ×1.3; on another CPU model, its ratio "
                   "to the reference matcher); writes nothing")


def run(args: argparse.Namespace) -> int:
    return time_run(args.run, args.per_stratum, args.warmup, args.reference, args.regenerate, seed=args.seed,
                    cores=args.cores, allow_contended=args.allow_contended, retries=args.retries,
                    wait_s=args.wait, verify=args.verify)


def time_run(run: Path, per_stratum: int | None = None, warmup: int | None = None, reference: str | None = None,
             regenerate: bool = False, *, seed: int | None = None, cores: list[int] | None = None,
             allow_contended: bool = False, retries: int | None = None, wait_s: float | None = None,
             verify: bool = False) -> int:
    """The verb on the run directory ``run`` (its options as arguments; the study step
    ``timing`` calls it): a progress bar, the pass (or its verification), the exit status."""
    from tqdm import tqdm

    from tfloc.errors import ConfigError
    from tfloc.harness.timing_pass import RETRIES, WAIT_S, timing_pass
    from tfloc.harness.timing_verify import verify_pass
    from tfloc.report.timing import write_timing_md

    bars: list[tqdm] = []  # made at the first scan timed (none when the pass is current)

    def progress(done: int, total: int) -> None:
        if not bars:
            bars.append(tqdm(total=total, unit="scan", desc="timing", disable=not sys.stderr.isatty()))
        bars[0].update(done - bars[0].n)

    retries = RETRIES if retries is None else retries
    wait_s = WAIT_S if wait_s is None else wait_s
    if retries < 0 or wait_s < 0:
        raise ConfigError(f"--retries and --wait must be ≥ 0, got {retries} and {wait_s:g}")
    try:
        if verify:
            return 0 if verify_pass(run, per_stratum, cores, log=print, allow_contended=allow_contended,
                                    retries=retries, wait_s=wait_s, progress=progress) else 1
        timing_pass(run, per_stratum, warmup, reference, regenerate, progress, seed=seed, cores=cores,
                    log=lambda s: tqdm.write(s, file=sys.stderr), allow_contended=allow_contended, draw=write_timing_md,
                    retries=retries, wait_s=wait_s)
    finally:
        for bar in bars:
            bar.close()
    return 0
