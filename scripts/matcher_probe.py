"""Probe one matcher (with parameter overrides) on the first N scans of some datasets: success
(≤ 10 cm and ≤ 2°, tfloc's Thresholds), median errors and median CPU ms per scan, one thread.

A research script (issue 25: is it the wrapper or the algorithm?), not part of the benchmark:

    .venv/bin/python scripts/matcher_probe.py karto data/scenarios/real-intel-as-built \
        --param base_surface=near-face --scans 100
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from tfloc.core.matcher import get_matcher
from tfloc.core.pose import wrap_angle
from tfloc.evaluation.outcome import Thresholds
from tfloc.harness.task import load_dataset, problem_of
from tfloc.harness.threads import limit_threads


def _value(text: str) -> object:
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("matcher")
    ap.add_argument("datasets", nargs="+")
    ap.add_argument("--param", action="append", default=[], help="KEY=VALUE (JSON value or a string)")
    ap.add_argument("--scans", type=int, default=100, help="first N scans of each dataset (0: all)")
    args = ap.parse_args()
    limit_threads(1)
    params = {k: _value(v) for k, v in (p.split("=", 1) for p in args.param)}
    matcher = get_matcher(args.matcher, **params)
    th = Thresholds()
    for path in args.datasets:
        scenario, scans = load_dataset(path)
        rows = list(scans.values())[: args.scans or None]
        ok, cpu, dist, orient = [], [], [], []
        prep = getattr(matcher, "prepare", None)
        if prep is not None and rows:
            prep(problem_of(scenario, rows[0]))
        for s in rows:
            problem = problem_of(scenario, s)
            t0 = time.process_time()
            est = matcher.localize(problem)
            cpu.append(time.process_time() - t0)
            d = math.hypot(est.pose.x - s.true.x, est.pose.y - s.true.y)
            o = abs(wrap_angle(est.pose.theta - s.true.theta))
            dist.append(d)
            orient.append(o)
            ok.append(bool(th.success(d, o)))
        print(f"{args.matcher} {params} {path}: success {100 * np.mean(ok):.1f}% ({sum(ok)}/{len(ok)}), "
              f"median {100 * np.median(dist):.2f} cm / {math.degrees(np.median(orient)):.2f} deg, "
              f"CPU {1000 * np.median(cpu):.1f} ms median", flush=True)


if __name__ == "__main__":
    main()
