"""CPU time and accuracy of ``cv-corners`` on real-log scans, in one process (``time.process_time``).

The harness's ``runtime_s`` is wall time on a shared machine; this script times each ``localize``
call by the CPU time of this process (all its threads) instead. Scans are chosen per dataset
group by their position within the group (0-based, in ``scans.csv`` order), so a development and
a held-out subset can be named exactly::

    # development subset (parameters of cv-corners were chosen on these)
    python benchmarks/cv_corners_real.py --rows 0:20 data/scenarios/real-csail-relations \\
        --out /tmp/dev-rel.csv
    # held-out subset
    python benchmarks/cv_corners_real.py --rows 20:50 data/scenarios/real-csail-relations

``--set key=value`` overrides a :class:`tfloc.baselines.cv_corners.Config` field (JSON values).
Prints one summary line per dataset group and writes per-scan rows with ``--out``.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import time
from pathlib import Path

import numpy as np

import tfloc
from tfloc import Problem, angdiff
from tfloc.errors import TflocError
from tfloc.io.scenario import map_for, read_scans, read_scenario


def _rows(spec: str) -> slice:
    lo, _, hi = spec.partition(":")
    return slice(int(lo) if lo else None, int(hi) if hi else None)


def _summary(rows: list[dict]) -> str:
    """n, success rate, CPU ms median / p95 / max over the timed rows (invalid problems are failures, untimed)."""
    ms = np.array([r["cpu_ms"] for r in rows if not math.isnan(r["cpu_ms"])])
    invalid = sum(r["status"] == "invalid" for r in rows)
    cpu = (f"cpu ms median={np.median(ms):8.1f} p95={np.percentile(ms, 95):8.1f} max={ms.max():8.1f}"
           if ms.size else "cpu ms -")
    return (f"n={len(rows):3d} success={np.mean([r['success'] for r in rows]):6.1%} {cpu}"
            + (f" ({invalid} invalid)" if invalid else ""))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("datasets", nargs="+")
    ap.add_argument("--rows", default="0:5", help="positions within each group, start:stop (0-based)")
    ap.add_argument("--step", type=int, default=1, help="take every STEP-th row of the range")
    ap.add_argument("--groups", default="", help="comma-separated groups to keep (default all)")
    ap.add_argument("--set", action="append", default=[], help="Config override key=value (JSON value)")
    ap.add_argument("--matcher", default="cv-corners")
    ap.add_argument("--out", type=Path)
    args = ap.parse_args()
    overrides = {k: json.loads(v) for k, _, v in (s.partition("=") for s in args.set)}
    matcher = tfloc.get_matcher(args.matcher, **overrides)
    sl = _rows(args.rows)
    keep = set(filter(None, args.groups.split(",")))
    out_rows = []
    for d in args.datasets:
        scenario = read_scenario(d)
        by_group: dict[str, list] = {}
        for scan in read_scans(scenario):
            by_group.setdefault(scan.group, []).append(scan)
        cache: dict = {}
        first = next(iter(by_group.values()))[0]  # compile numba kernels before timing anything
        matcher.score(Problem(map_for(scenario, first, cache), scenario.laser, first.ranges, first.initial),
                      first.initial)
        for group, scans in by_group.items():
            if keep and group not in keep:
                continue
            chosen = scans[sl][:: args.step]
            for scan in chosen:
                try:
                    problem = Problem(map_for(scenario, scan, cache), scenario.laser, scan.ranges, scan.initial)
                except TflocError as exc:  # e.g. an odometry guess outside the reference scan's area
                    out_rows.append({"dataset": scenario.name, "group": group, "scan_id": scan.scan_id,
                                     "cpu_ms": math.nan, "dist_err_m": math.nan, "orient_err_deg": math.nan,
                                     "success": 0, "status": "invalid", "iterations": 0, "info": str(exc)})
                    continue
                t0 = time.process_time()
                est = matcher.localize(problem)
                cpu_ms = 1e3 * (time.process_time() - t0)
                d_err = est.pose.distance_to(scan.true)
                o_err = abs(angdiff(est.pose.theta, scan.true.theta))
                ok = est.info.get("status") != "no-answer" and d_err <= 0.10 and o_err <= math.radians(2.0)
                out_rows.append({"dataset": scenario.name, "group": group, "scan_id": scan.scan_id,
                                 "cpu_ms": cpu_ms, "dist_err_m": d_err, "orient_err_deg": math.degrees(o_err),
                                 "success": int(ok), "status": est.info.get("status", ""),
                                 "iterations": est.iterations,
                                 "info": json.dumps(est.info, default=str, separators=(",", ":"))})
            rows = [r for r in out_rows if r["dataset"] == scenario.name and r["group"] == group]
            if rows:
                print(f"{scenario.name:24s} {group:6s} {_summary(rows)}", flush=True)
        rows = [r for r in out_rows if r["dataset"] == scenario.name]
        if rows:
            print(f"{scenario.name:24s} {'(all)':6s} {_summary(rows)}", flush=True)
    print(f"{'all':31s} {_summary(out_rows)}")
    if args.out:
        with args.out.open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(out_rows[0]))
            w.writeheader()
            w.writerows(out_rows)


if __name__ == "__main__":
    main()
