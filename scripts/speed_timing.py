"""CPU time per scan of tf-plus, tf, tf-best, csm-corr and cv-corners, interleaved, one thread,
and every answer written out (to compare two checkouts' poses bit for bit).

Run from a checkout (``PYTHONPATH`` selects which tfloc is imported)::

    OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 PYTHONPATH=. .venv/bin/python scripts/speed_timing.py \
        --out /tmp/after.csv [--per 4 --per-real 40 --matchers tf-plus tf]

Writes one row per (dataset, scan, matcher): est_x/est_y/est_theta (repr, exact) and cpu_ms,
and prints the medians per matcher and paper/real part, with the ratio to csm-corr.
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))
from _sample import add_sample_args, one_core, sample  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    add_sample_args(ap)
    ap.add_argument("--matchers", nargs="+", default=["tf-plus", "tf", "csm-corr", "cv-corners"])
    ap.add_argument("--repeat", type=int, default=1, help="timed calls per scan and matcher (min kept)")
    a = ap.parse_args()
    one_core()
    import numpy as np

    import tfloc
    from tfloc.core.matcher import get_matcher
    print("tfloc from", os.path.dirname(tfloc.__file__), file=sys.stderr)

    probs = sample(tuple(a.datasets), a.per, a.per_real)
    matchers = {m: get_matcher(m) for m in a.matchers}
    warmed = set()
    rows = []
    for i, (ds, sid, prob) in enumerate(probs):
        order = a.matchers[i % len(a.matchers):] + a.matchers[:i % len(a.matchers)]
        for m in order:
            mt = matchers[m]
            if (ds, m) not in warmed:
                warmed.add((ds, m))
                if hasattr(mt, "prepare"):
                    mt.prepare(prob)
                mt.score(prob, prob.initial)
                mt.localize(prob)
            best = np.inf
            for _ in range(a.repeat):
                c0 = time.process_time()
                est = mt.localize(prob)
                best = min(best, time.process_time() - c0)
            p = est.pose
            rows.append({"dataset": ds, "scan_id": sid, "matcher": m, "est_x": repr(p.x),
                         "est_y": repr(p.y), "est_theta": repr(p.theta), "cpu_ms": best * 1e3})
    with open(a.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    import pandas as pd
    df = pd.DataFrame(rows)
    df["part"] = np.where(df.dataset.str.startswith("real-"), df.dataset, "paper")
    med = df.groupby(["part", "matcher"]).cpu_ms.median().unstack()
    if "csm-corr" in med:
        print((med.div(med["csm-corr"], axis=0)).round(3).add_suffix(" /csm").to_string())
    print(med.round(2).to_string())
    print(df.groupby(["part", "matcher"]).size().unstack().to_string())


if __name__ == "__main__":
    main()
