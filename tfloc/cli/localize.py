"""Localize every scan of a scenario dataset with one matcher and write one CSV row per scan.

Only the initial pose and the ranges are read; the dataset's true_* fields may be empty.
Rows are written as scans finish, so a long run can be watched (and its output is never lost).
The matcher is built before the output is opened: an unknown parameter or a bad value stops the
command at once (exit 2), naming the --param. A scan whose problem cannot be posed (e.g. its
initial pose lies outside the map) gets status `invalid:<reason>`; a matcher that raises gets
`error:<message>` and the command goes on, then exits 3.
runtime_s is the wall time of each localize call, cpu_s its CPU time (this process, which runs
every library on one thread); the matcher is warmed up on the first scan before timing.

Example:
  tfloc localize --dataset data/scenarios/office-pool --matcher tf --out estimates.csv
  tfloc localize --dataset data/scenarios/detail-1 --matcher tf-plus --param grid_step=0.1
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

from tqdm import tqdm

from tfloc.core.matcher import check_solvable
from tfloc.core.result import Status, StatusKind
from tfloc.core.tracker import has_single_scan_mode
from tfloc.errors import ConfigError, InvalidProblemError
from tfloc.harness.threads import limit_threads
from tfloc.harness.workspace import (
    problem_of,
    status_of,
    timed_localize,
    use_map,
    warm,
)
from tfloc.io.rundir import ESTIMATES
from tfloc.io.scenario import iter_scans, read_scenario

from ._matcher import matcher_from_args

HELP = "localize the scans of a dataset with one matcher (no scoring)"
COLUMNS = ["scan_id", "matcher", "est_x", "est_y", "est_theta", "runtime_s", "cpu_s", "converged",
           "iterations", "evaluations", "status"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dataset", required=True, type=Path, help="scenario dataset directory "
                   "(scenario.json + scans.csv)")
    p.add_argument("--map", type=Path, default=None,
                   help="map file (.geojson or ROS .yaml); default: the map named in scenario.json")
    p.add_argument("--matcher", default="tf", help="registered matcher name (default: tf)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="a matcher parameter, VALUE in TOML syntax (repeatable): --param spacing=0.5, "
                        "--param gates=[1.0,0.5], --param select=tf")
    p.add_argument("--out", type=Path, default=Path(ESTIMATES),
                   help="output CSV, one row per scan (default: estimates.csv)")
    p.add_argument("--limit", type=int, default=None, help="only the first N scans")


def run(args: argparse.Namespace) -> int:
    limit_threads(1)
    scenario = read_scenario(args.dataset)
    matcher = matcher_from_args(args.matcher, args.param, "localize")
    if not has_single_scan_mode(matcher):
        raise ConfigError(f"matcher {args.matcher!r} is a tracker with no single-scan mode: use tfloc track")
    if args.map is not None:
        from tfloc.io.maps import load_map

        use_map(scenario, load_map(args.map))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    counts = {"ok": 0, "failed": 0, "invalid": 0, "error": 0}
    with args.out.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        scans = iter_scans(scenario)
        for n, scan in enumerate(tqdm(scans, desc=f"{matcher.name}", unit="scan",
                                      disable=not sys.stderr.isatty())):
            if args.limit is not None and n >= args.limit:
                break
            w.writerow(_localize(matcher, scenario, scan, counts, first=n == 0))
            fh.flush()
    print(f"wrote {args.out}: " + ", ".join(f"{k} {v}" for k, v in counts.items()), file=sys.stderr)
    return 3 if counts["error"] else 0


def _localize(matcher, scenario, scan, counts: dict, first: bool) -> list:
    """One output row: the estimate, or an ``invalid:``/``error:`` status without one."""
    try:
        problem = problem_of(scenario, scan)
        check_solvable(matcher, problem)
    except InvalidProblemError as exc:
        counts["invalid"] += 1
        return [scan.scan_id, matcher.name, *[""] * 8, str(Status.of(StatusKind.INVALID, str(exc)))]
    try:
        if first:  # untimed; a scan-to-scan map is new for each problem, so not warmed here
            warm(matcher, problem_of(scenario, scan))
        t = timed_localize(matcher, problem)
    except Exception as exc:  # noqa: BLE001 - a failing matcher is a result, as in tfloc bench
        counts["error"] += 1
        return [scan.scan_id, matcher.name, *[""] * 8, str(Status.of(StatusKind.ERROR, f"{type(exc).__name__}: {exc}"))]
    est = t.estimate
    status = status_of(est)
    counts[status.kind.value] += 1
    return [scan.scan_id, matcher.name, f"{est.pose.x:.6f}", f"{est.pose.y:.6f}", f"{est.pose.theta:.7f}",
            f"{t.wall_s:.6f}", f"{t.cpu_s:.6f}", int(est.converged), est.iterations, est.evaluations, str(status)]
