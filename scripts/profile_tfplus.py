"""One-off research: where tf-plus's CPU time goes, per stage (one process, one thread, warm caches).

Runs each stage of ``TurningFunctionPlusMatcher.localize`` (default configuration) by hand
with a CPU timer around it, on the speed scripts' sample (:mod:`_sample`), and prints the
median CPU µs per stage and scan for the paper protocol and for each real dataset::

    OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 PYTHONPATH=. .venv/bin/python scripts/profile_tfplus.py

The stages follow the matcher's code of this checkout; where a stage is fused with the next
(``staged`` returns what it ran), its time is reported under the first name.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))
from _sample import PAPER, add_sample_args, one_core, sample  # noqa: E402


def staged(matcher, problem) -> dict[str, float]:
    """CPU seconds per stage of one localize call (default configuration)."""
    from tfloc.tfplus import matcher as mm
    from tfloc.tfplus.coarse import candidates

    cfg = matcher.config
    t: dict[str, float] = {}
    clock = time.process_time
    c0 = clock()
    points = problem.points
    t["points"] = clock() - c0
    c0 = clock()
    heads, _ = mm.heading_seeds(problem, cfg)
    t["headings (tf seeds)"] = clock() - c0
    vp = problem.initial
    c0 = clock()
    field = mm._field(problem.map, cfg)
    coarse_field = mm._coarse_field(problem.map, cfg)
    t["view look-up"] = clock() - c0
    c0 = clock()
    positions = mm.lattice(problem.map, field, vp.xy, cfg.search_radius, cfg.grid_step, cfg.clearance)
    t["lattice (free positions)"] = clock() - c0
    c0 = clock()
    stride = max(1, len(points) // cfg.coarse_points)
    cands, _, _ = candidates(coarse_field, points, positions, heads, stride, cfg.shortlist,
                             cfg.candidates, cfg.separation, cfg.grid_step)
    t["coarse search + candidates"] = clock() - c0
    c0 = clock()
    if isinstance(problem.map, mm.GridMap):
        cands = mm.refine_to_field(field, points, cands, cfg.refinement)
    else:
        cands = mm.refine(problem.map, problem.laser, points, cands, cfg.refinement)
    t["refinement"] = clock() - c0
    c0 = clock()
    cost = matcher._cost(problem, cands)
    t["selection cost"] = clock() - c0
    c0 = clock()
    mm.pick(cost, cands, vp, cfg.tie_tolerance)
    t["pick"] = clock() - c0
    return t


def main() -> None:
    ap = argparse.ArgumentParser()
    add_sample_args(ap)
    a = ap.parse_args()
    one_core()
    import numpy as np
    import pandas as pd

    from tfloc.core.matcher import get_matcher

    m = get_matcher("tf-plus")
    probs = sample(tuple(a.datasets), a.per, a.per_real)
    rows = []
    seen = set()
    for ds, _sid, prob in probs:
        if ds not in seen:
            seen.add(ds)
            m.prepare(prob)
            m.localize(prob)
            staged(m, prob)
        t = staged(m, prob)
        c0 = time.process_time()
        m.localize(prob)
        whole = time.process_time() - c0
        part = "paper" if ds in PAPER else ds
        rows += [{"part": part, "stage": k, "us": v * 1e6} for k, v in t.items()]
        rows.append({"part": part, "stage": "sum of stages", "us": sum(t.values()) * 1e6})
        rows.append({"part": part, "stage": "localize (whole call)", "us": whole * 1e6})
    df = pd.DataFrame(rows)
    order = list(dict.fromkeys(df.stage))
    med = df.groupby(["stage", "part"], sort=False).us.median().unstack().reindex(order)
    mean = df.groupby(["stage", "part"], sort=False).us.mean().unstack().reindex(order)
    print("median CPU µs per scan")
    print(med.round(0).to_string())
    print("mean CPU µs per scan")
    print(mean.round(0).to_string())
    print("scans:", df[df.stage == "pick"].groupby("part").size().to_dict(), np.__version__)


if __name__ == "__main__":
    main()
