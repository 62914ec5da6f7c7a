"""Measure ``bnb-global`` on the global datasets (issue 24): top-1, top-5, ambiguous, CPU ms per scan,
the map's free area, the precomputed grids' memory and build time.

One process, every thread pool limited to one thread; runtimes are CPU time
(``time.process_time``) of ``localize`` alone, the map's grids built beforehand (``prepare``,
timed apart). Scans: ``--per-set`` evenly spaced rows of each dataset (all groups in proportion).

    .venv/bin/python scripts/bnb_global_measure.py --out results/bnb-global --per-set 50
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import platform
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

from tfloc.harness.threads import limit_threads

EVAL_SETS = ("global-office-1", "global-office-2", "global-office-3",
             "real-intel-global", "real-csail-global", "real-aces-global")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("results/bnb-global"))
    ap.add_argument("--per-set", type=int, default=50)
    ap.add_argument("--sets", nargs="*", default=list(EVAL_SETS))
    ap.add_argument("--data", type=Path, default=Path("data/scenarios"))
    ap.add_argument("--params", default="{}", help="bnb-global parameters as JSON")
    args = ap.parse_args()
    limit_threads(1)

    from tfloc.baselines.bnb_global import BranchAndBoundGlobalMatcher

    from tfloc.core.matcher import get_matcher
    from tfloc.core.pose import angdiff
    from tfloc.core.problem import Problem
    from tfloc.evaluation.outcome import Thresholds
    from tfloc.evaluation.relocalization import free_area_m2, scan_result, summarize
    from tfloc.io.scenario import map_for, read_scans, read_scenario

    params = json.loads(args.params)
    matcher: BranchAndBoundGlobalMatcher = get_matcher("bnb-global", **params)  # type: ignore[assignment]
    thresholds = Thresholds()
    args.out.mkdir(parents=True, exist_ok=True)
    results, areas, maps_info, rows = [], {}, [], []
    for ds in args.sets:
        sc = read_scenario(args.data / ds)
        scans = read_scans(sc)
        pick = np.unique(np.linspace(0, len(scans) - 1, min(args.per_set, len(scans))).round().astype(int))
        m = map_for(sc, scans[0])
        t0 = time.process_time()
        matcher.prepare(Problem(m, sc.laser, scans[0].ranges, None))
        build_s = time.process_time() - t0
        grid = matcher._grid(Problem(m, sc.laser, scans[0].ranges, None))
        areas[ds] = free_area_m2(m)
        maps_info.append({"dataset": ds, "map": sc.map_path.name, "free_area_m2": round(areas[ds], 1),
                          "grid_cells": int(grid.prob.size), "grids_MiB": round(grid.nbytes / 2**20, 2),
                          "build_cpu_s": round(build_s, 3)})
        for j in pick:
            s = scans[j]
            p = Problem(m, sc.laser, s.ranges, None)
            t0 = time.process_time()
            est = matcher.localize(p)
            cpu = time.process_time() - t0
            ans = est.pose if est.info.get("status") != "no-answer" else None
            se = matcher.score(p, est.pose) if ans is not None else math.nan
            st = matcher.score(p, s.true)
            r = scan_result(ds, "bnb-global", s.true, ans, est.hypotheses, thresholds, se, st, cpu)
            results.append((s.group, r))
            d = ans.distance_to(s.true) if ans is not None else math.nan
            o = abs(math.degrees(angdiff(ans.theta, s.true.theta))) if ans is not None else math.nan
            rows.append({"dataset": ds, "scan_id": s.scan_id, "group": s.group, "answered": r.answered,
                         "top1": r.top1, "top5": r.top5, "ambiguous": r.ambiguous,
                         "dist_err_m": round(d, 4), "orient_err_deg": round(o, 3),
                         "cpu_ms": round(cpu * 1e3, 1), "score_est": round(se, 4), "score_true": round(st, 4),
                         "headings": est.info.get("headings"), "candidates": est.info.get("candidates_scored")})
            print(json.dumps(rows[-1]), flush=True)
    with (args.out / "scans.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    summ = summarize([r for _, r in results], areas)
    by_group = []
    for ds in args.sets:
        for g in ("real", "sim"):
            rs = [r for gg, r in results if r.dataset == ds and gg == g]
            if rs and len({gg for gg, r in results if r.dataset == ds}) > 1:
                by_group += [(g, s) for s in summarize(rs, areas)]
    with (args.out / "summary.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["group", *asdict(summ[0])])
        w.writeheader()
        for g, s in [("all", s) for s in summ] + by_group:
            w.writerow({"group": g, **asdict(s)})
    with (args.out / "maps.json").open("w") as fh:
        json.dump({"maps": maps_info, "params": asdict(matcher.config), "per_set": args.per_set,
                   "thresholds": thresholds.to_dict(), "machine": platform.node(),
                   "load_average": os.getloadavg()}, fh, indent=2)
    print("\n| dataset | group | n | top-1 % [95 % CI] | top-5 % [95 % CI] | ambiguous % | no answer % | "
          "CPU ms median | free area m² | ms per 100 m² |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for g, s in [("all", s) for s in summ] + by_group:
        print(f"| {s.dataset} | {g} | {s.n} | {100 * s.top1:.0f} [{100 * s.top1_lo:.0f}–{100 * s.top1_hi:.0f}] | "
              f"{100 * s.top5:.0f} [{100 * s.top5_lo:.0f}–{100 * s.top5_hi:.0f}] | {100 * s.ambiguous:.0f} | "
              f"{100 * s.no_answer:.0f} | {s.cpu_ms_median:.0f} | {s.free_area_m2:.0f} | {s.ms_per_100m2:.1f} |")
    print("\n| map | free area m² | grid cells | precomputed grids MiB | build CPU s |")
    print("|---|---|---|---|---|")
    for mi in maps_info:
        print(f"| {mi['dataset']} ({mi['map']}) | {mi['free_area_m2']} | {mi['grid_cells']} | "
              f"{mi['grids_MiB']} | {mi['build_cpu_s']} |")


if __name__ == "__main__":
    main()
