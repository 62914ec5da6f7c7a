"""Measure tracking: every given matcher (and dead reckoning) along every given sequence dataset.

One process, one thread (CPU times per step: ``time.process_time``). Rows go to
``OUT/estimates.csv`` (columns of tfloc.io.estimates.COLUMNS), one (sequence, matcher) at a time,
appended as each finishes; a rerun skips the (sequence, matcher) pairs already there.

  .venv/bin/python scripts/track_measure.py --out results/tracking-dev \
      --matchers tf-plus csm-corr o3d-icp kiss-icp -- data/scenarios/seq-*
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--matchers", nargs="+", default=["tf-plus", "csm-corr", "o3d-icp", "kiss-icp"])
    ap.add_argument("datasets", nargs="+", type=Path)
    args = ap.parse_args()

    from tfloc.harness.threads import limit_threads

    limit_threads(1)
    from tfloc.core.matcher import get_matcher
    from tfloc.harness.track import dead_reckoning, track
    from tfloc.io.estimates import COLUMNS
    from tfloc.io.scenario import read_scans, read_scenario

    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "estimates.csv"
    done = set()
    if path.exists():
        with path.open() as fh:
            done = {(r["dataset"], r["matcher"]) for r in csv.DictReader(fh)}
    new = not path.exists()
    with path.open("a", newline="") as fh:
        w = csv.DictWriter(fh, COLUMNS)
        if new:
            w.writeheader()
        for d in args.datasets:
            scenario = read_scenario(d)
            scans = read_scans(scenario)
            for name in ["odometry", *args.matchers]:
                if (scenario.name, name) in done:
                    continue
                t0, c0 = time.perf_counter(), time.process_time()
                rows = (dead_reckoning(scenario, scans) if name == "odometry"
                        else track(scenario, scans, get_matcher(name)))
                w.writerows(rows)
                fh.flush()
                print(f"{scenario.name} {name}: {len(rows)} scans, cpu {time.process_time() - c0:.1f} s, "
                      f"wall {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
