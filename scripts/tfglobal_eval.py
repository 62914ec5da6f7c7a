"""Research script for ``tf-global`` (docs/tf-global.md): development and held-out sets of global
problems, place recall of signature variants, end-to-end success and CPU time, index growth.

Sets (simulated: LMS200, σ = 1 cm, poses uniform over free space ≥ 0.3 m from walls, headings
uniform; seeds distinct from every bundled dataset):
  dev      office-1 + office-2, 50 scans each, seed 24001 / 24002 (tuning only)
  heldout  office-3, 100 scans, seed 24003 (never used for tuning)
  real-*   every k-th scan of data/scenarios/real-*-scan-to-map, init blanked (truth = corrected pose)

Usage (one thread; CPU time):
  OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 .venv/bin/python scripts/tfglobal_eval.py recall dev
  ... scripts/tfglobal_eval.py run dev [key=value ...]     (tf-global parameters, JSON values)
  ... scripts/tfglobal_eval.py index                        (build time / size vs free area)
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose, angdiff
from tfloc.core.problem import Problem
from tfloc.datasets.noise import NoiseModel
from tfloc.datasets.synthetic import sample_free_pose
from tfloc.evaluation.stats import wilson
from tfloc.harness.threads import limit_threads
from tfloc.io.maps import load_map
from tfloc.io.scenario import iter_scans, read_scenario
from tfloc.relocalize.index import IndexConfig, place_index
from tfloc.relocalize.matcher import TurningFunctionGlobalMatcher
from tfloc.relocalize.signature import SignatureConfig, scan_signature

ROOT = Path(__file__).resolve().parents[1]
SIM = {"dev": [("office-1", 24001, 50), ("office-2", 24002, 50)],
       "heldout": [("office-3", 24003, 100)]}
REAL = {"real-intel": "real-intel-scan-to-map", "real-csail": "real-csail-scan-to-map",
        "real-aces": "real-aces-scan-to-map"}


def simulated(name: str, seed: int, n: int):
    m = load_map(ROOT / "data" / "maps" / f"{name}.geojson")
    laser, noise, rng = LaserSpec.lms200(), NoiseModel(), np.random.default_rng(seed)
    out = []
    for _ in range(n):
        true = sample_free_pose(m, rng, 0.3)
        out.append((true, noise.apply(m.raycast(true, laser), laser, rng)))
    return m, laser, out


def real(name: str, n: int):
    sc = read_scenario(ROOT / "data" / "scenarios" / REAL[name])
    m = load_map(sc.map_path)
    scans = list(iter_scans(sc))
    stride = max(1, len(scans) // n)
    return m, sc.laser, [(s.true, s.ranges) for s in scans[::stride][:n]]


def sets(which: str, n_real: int = 100):
    if which in SIM:
        return [(name, *simulated(name, seed, n)) for name, seed, n in SIM[which]]
    return [(which, *real(which, n_real))]


def ok(a: Pose, b: Pose, d: float = 0.10, o: float = math.radians(2.0)) -> bool:
    return a.distance_to(b) <= d and abs(angdiff(a.theta, b.theta)) <= o


def recall(which: str, ks=(1, 3, 5, 8, 12, 16, 24, 42, 70), step: float = 0.35, headings: int = 16,
           **sig) -> dict:
    """Place recall@k: an entry among the k nearest distinct places within 0.5 m and 25° of the
    truth (what tf-plus's resolver can reach from it)."""
    cfg = IndexConfig(step=step, headings=headings, signature=SignatureConfig(**sig))
    hits = np.zeros(len(ks))
    n = 0
    for _, m, laser, scans in sets(which):
        idx = place_index(m, laser, cfg, disk=False)
        for true, ranges in scans:
            e, _ = idx.query(scan_signature(ranges, laser, cfg.signature), max(ks), 0.75,
                             math.radians(30))
            p = idx.poses[e]
            near = (np.hypot(p[:, 0] - true.x, p[:, 1] - true.y) <= 0.5) & (
                np.abs(angdiff(p[:, 2], true.theta)) <= math.radians(25))
            first = np.flatnonzero(near)
            for i, k in enumerate(ks):
                hits[i] += bool(first.size and first[0] < k)
            n += 1
    return {"n": n, **{f"@{k}": round(float(h / n), 3) for k, h in zip(ks, hits, strict=True)}}


def run(which: str, **params) -> dict:
    matcher = TurningFunctionGlobalMatcher(**params)
    rows = []
    for name, m, laser, scans in sets(which):
        matcher.prepare(Problem(m, laser, scans[0][1], None))
        for i, (true, ranges) in enumerate(scans):
            p = Problem(m, laser, ranges, None, where=f"{name}:{i}")
            c0 = time.process_time()
            est = matcher.localize(p)
            cpu = time.process_time() - c0
            top1 = ok(est.pose, true)
            top5 = any(ok(h, true) for h in est.hypotheses[:5])
            amb = (not top1) and est.pose.is_finite() and matcher.score(p, est.pose) <= matcher.score(p, true)
            rows.append({"set": name, "i": i, "top1": top1, "top5": top5, "ambiguous": amb,
                         "cpu_ms": 1000 * cpu, "err_m": est.pose.distance_to(true)})
    out = {}
    for name in [*dict.fromkeys(r["set"] for r in rows), "all"]:
        rs = [r for r in rows if name in ("all", r["set"])]
        k1 = sum(r["top1"] for r in rs)
        out[name] = {"n": len(rs), "top1": round(k1 / len(rs), 3),
                     "top1_ci95": [round(v, 3) for v in wilson(k1, len(rs))],
                     "top5": round(np.mean([r["top5"] for r in rs]), 3),
                     "ambiguous": int(sum(r["ambiguous"] for r in rs)),
                     "cpu_ms_median": round(float(np.median([r["cpu_ms"] for r in rs])), 1),
                     "cpu_ms_p90": round(float(np.percentile([r["cpu_ms"] for r in rs], 90)), 1)}
    return out


def index_growth(**params) -> list[dict]:
    """Index build CPU time (stored with the index when it was built), load time, memory and
    disk size per map, against the map's free area."""
    from tfloc.relocalize.index import default_cache_dir, index_key, load_or_build
    cfg = IndexConfig(**params)
    out = []
    for name in ("office-1", "office-2", "office-3", "real-intel", "real-csail", "real-aces"):
        if name.startswith("real"):
            m, laser, _ = real(name, 1)
        else:
            m, laser = load_map(ROOT / "data" / "maps" / f"{name}.geojson"), LaserSpec.lms200()
        idx = load_or_build(m, laser, cfg)
        path = default_cache_dir() / f"{index_key(m, laser, cfg)}.npz"
        c0 = time.process_time()
        load_or_build(m, laser, cfg)
        load_s = time.process_time() - c0
        out.append({"map": name, "free_m2": round(idx.free_area_m2, 1), "entries": len(idx.poses),
                    "build_cpu_s": round(idx.build_cpu_s, 2), "load_cpu_s": round(load_s, 3),
                    "memory_mib": round(idx.nbytes / 2**20, 2),
                    "disk_mib": round(path.stat().st_size / 2**20, 2)})
        print(json.dumps(out[-1]), flush=True)
    return out


def write(which: str, out: str) -> None:
    """Write a simulated set as global datasets ``out/<map>-global`` (truth kept) and
    ``out/<map>-global-blind`` (truth blanked), e.g. for ``tfloc localize``."""
    from tfloc.io.scenario import Scan, write_scenario
    for name, _, laser, scans in sets(which):
        for suffix, keep in (("", True), ("-blind", False)):
            rows = [Scan(f"g{i:03d}", "global", r, None, t if keep else None)
                    for i, (t, r) in enumerate(scans)]
            write_scenario(Path(out) / f"{name}-global{suffix}", f"{name}-global{suffix}",
                           ROOT / "data" / "maps" / f"{name}.geojson", laser, rows,
                           description=f"tf-global {which} set", mode="global")


def main(argv: list[str]) -> None:
    limit_threads(1)
    cmd, *rest = argv
    kv = {k: json.loads(v) for k, _, v in (a.partition("=") for a in rest[1:] if "=" in a)}
    if cmd == "recall":
        print(json.dumps({"set": rest[0], **kv, **recall(rest[0], **kv)}), flush=True)
    elif cmd == "run":
        print(json.dumps({"set": rest[0], **kv, **run(rest[0], **kv)}), flush=True)
    elif cmd == "write":
        write(rest[0], rest[1])
    elif cmd == "index":
        index_growth(**{k: json.loads(v) for k, _, v in (a.partition("=") for a in rest)})


if __name__ == "__main__":
    main(sys.argv[1:])
