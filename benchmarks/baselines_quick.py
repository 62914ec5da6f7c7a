"""Quick accuracy/runtime check of matchers on the bundled test room (fixed seed, ~90 problems).

Problems: true poses drawn in free space (≥ 0.3 m from walls) of ``data/maps/test-room.geojson``,
the LMS200 scan ray-cast from the true pose plus N(0, 1 cm) range noise, and an initial pose offset
from the truth by a distance in one of the bins 0–1, 1–2, 2–3 m (uniform within the bin, random
direction) and an angle in one of 0–5°, 5–10°, 10–15° (uniform, random sign); ``--per-cell``
problems per (distance, angle) cell. Success = distance error ≤ 10 cm and orientation error ≤ 2°.

Run::

    PYTHONPATH=$PWD python benchmarks/baselines_quick.py --matchers o3d-icp kiss-icp csm-corr cv-corners
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import tfloc
from tfloc import LaserSpec, Pose, Problem, angdiff

ROOT = Path(__file__).resolve().parents[1]
DIST_BINS = ((0.0, 1.0), (1.0, 2.0), (2.0, 3.0))
ANGLE_BINS_DEG = ((0.0, 5.0), (5.0, 10.0), (10.0, 15.0))


def make_problems(per_cell: int = 10, seed: int = 0) -> list[tuple[Problem, Pose, int]]:
    """``(problem, true pose, distance-bin index)`` for every cell, fixed seed."""
    rng = np.random.default_rng(seed)
    m = tfloc.load_map(ROOT / "data/maps/test-room.geojson")
    laser = LaserSpec.lms200()
    x0, y0, x1, y1 = m.bounds
    out = []
    for di, (dlo, dhi) in enumerate(DIST_BINS):
        for alo, ahi in ANGLE_BINS_DEG:
            n = 0
            while n < per_cell:
                true = Pose(rng.uniform(x0, x1), rng.uniform(y0, y1), rng.uniform(-math.pi, math.pi))
                if not m.is_free(true.xy[None], 0.3)[0]:
                    continue
                d, phi = rng.uniform(dlo, dhi), rng.uniform(-math.pi, math.pi)
                a = math.radians(rng.uniform(alo, ahi)) * rng.choice((-1.0, 1.0))
                init = Pose(true.x + d * math.cos(phi), true.y + d * math.sin(phi), true.theta + a)
                if not m.is_free(init.xy[None], 0.0)[0]:
                    continue
                ranges = m.raycast(true, laser)
                if laser.valid(ranges).sum() < 20:
                    continue
                ranges = ranges + rng.normal(0.0, 0.01, ranges.shape)
                out.append((Problem(m, laser, ranges, init), true, di))
                n += 1
    return out


def evaluate(name: str, problems: list[tuple[Problem, Pose, int]]) -> dict:
    """Run matcher ``name`` on every problem; per-bin success, median errors, ms per scan."""
    matcher = tfloc.get_matcher(name)
    matcher.localize(problems[0][0])  # warm caches (map geometry, fields) outside the timing
    rows = []
    for problem, true, di in problems:
        t0 = time.perf_counter()
        est = matcher.localize(problem)
        ms = 1e3 * (time.perf_counter() - t0)
        de = est.pose.distance_to(true)
        ae = abs(math.degrees(angdiff(est.pose.theta, true.theta)))
        rows.append((di, de, ae, ms, de <= 0.10 and ae <= 2.0))
    r = np.array(rows, dtype=float)
    res = {"matcher": name, "ms_median": float(np.median(r[:, 3])), "ms_p95": float(np.percentile(r[:, 3], 95))}
    ok = r[:, 4] > 0
    for di, (lo, hi) in enumerate(DIST_BINS):
        sel = r[:, 0] == di
        res[f"succ_{lo:g}-{hi:g}m"] = float(np.mean(ok[sel]))
    res["succ_all"] = float(np.mean(ok))
    res["med_dist_cm_ok"] = float(np.median(r[ok, 1]) * 100) if ok.any() else float("nan")
    res["med_orient_deg_ok"] = float(np.median(r[ok, 2])) if ok.any() else float("nan")
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--matchers", nargs="+", default=["o3d-icp", "kiss-icp", "csm-corr", "cv-corners"])
    ap.add_argument("--per-cell", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    problems = make_problems(args.per_cell, args.seed)
    cols = ["matcher", "succ_0-1m", "succ_1-2m", "succ_2-3m", "succ_all",
            "med_dist_cm_ok", "med_orient_deg_ok", "ms_median", "ms_p95"]
    print(f"{len(problems)} problems in test-room; success = ≤ 10 cm and ≤ 2°")
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for name in args.matchers:
        try:
            res = evaluate(name, problems)
        except tfloc.TflocError as exc:
            print(f"| {name} | {exc} |")
            continue
        print("| " + " | ".join(res[c] if c == "matcher" else f"{res[c]:.2f}" for c in cols) + " |")


if __name__ == "__main__":
    main()
