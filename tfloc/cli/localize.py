"""Localize every scan of a scenario dataset with one matcher and write one CSV row per scan.

Only the initial pose and the ranges are read; the dataset's true_* fields may be empty.
Rows are written as scans finish, so a long run can be watched (and its output is never lost).
runtime_s is the wall time of each localize call, cpu_s its CPU time (this process, which runs
every library on one thread); the matcher is warmed up on the first scan before timing.

Example:
  tfloc localize --dataset data/scenarios/office-pool --matcher tf --out estimates.csv
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

from tqdm import tqdm

from tfloc.core.matcher import get_matcher
from tfloc.core.problem import Problem
from tfloc.harness.task import status_of, warm
from tfloc.harness.threads import limit_threads
from tfloc.io.scenario import iter_scans, map_for, read_scenario

HELP = "localize the scans of a dataset with one matcher (no scoring)"
COLUMNS = ["scan_id", "matcher", "est_x", "est_y", "est_theta", "runtime_s", "cpu_s", "converged",
           "iterations", "evaluations", "status"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dataset", required=True, type=Path, help="scenario dataset directory "
                   "(scenario.json + scans.csv)")
    p.add_argument("--map", type=Path, default=None,
                   help="map file (.geojson or ROS .yaml); default: the map named in scenario.json")
    p.add_argument("--matcher", default="tf", help="registered matcher name (default: tf)")
    p.add_argument("--out", type=Path, default=Path("estimates.csv"),
                   help="output CSV, one row per scan (default: estimates.csv)")
    p.add_argument("--limit", type=int, default=None, help="only the first N scans")


def run(args: argparse.Namespace) -> int:
    limit_threads(1)
    scenario = read_scenario(args.dataset)
    matcher = get_matcher(args.matcher)
    cache: dict = {}
    if args.map is not None:
        from tfloc.io.maps import load_map

        cache[scenario.map_path] = load_map(args.map)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with args.out.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        scans = iter_scans(scenario)
        for n, scan in enumerate(tqdm(scans, desc=f"{matcher.name}", unit="scan",
                                      disable=not sys.stderr.isatty())):
            if args.limit is not None and n >= args.limit:
                break
            where = f"{scenario.scans_path}:{scan.line}"
            if n == 0:  # untimed; a scan-to-scan map is new for each map_for call, so not warmed here
                warm(matcher, Problem(map_for(scenario, scan, cache), scenario.laser, scan.ranges,
                                      scan.initial, where=where))
            problem = Problem(map_for(scenario, scan, cache), scenario.laser, scan.ranges,
                              scan.initial, where=where)
            t0, c0 = time.perf_counter(), time.process_time()
            est = matcher.localize(problem)
            dt, cpu = time.perf_counter() - t0, time.process_time() - c0
            w.writerow([scan.scan_id, matcher.name, f"{est.pose.x:.6f}", f"{est.pose.y:.6f}",
                        f"{est.pose.theta:.7f}", f"{dt:.6f}", f"{cpu:.6f}", int(est.converged), est.iterations,
                        est.evaluations, status_of(est)])
            fh.flush()
    print(f"wrote {args.out}", file=sys.stderr)
    return 0
