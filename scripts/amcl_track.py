"""Measure the ``amcl`` tracker (and, for scale, dead reckoning and ``tf-plus`` run as a tracker) on
two sequences, one CPU thread, CPU time per scan. Research script (issue 23, item 5), not part of
the package; the sequence datasets, the tracking loop and the evo metrics of issue 23 are built
elsewhere.

* ``sim``: a 5 Hz route through office-1 (corridor, three rooms through their doors, turns in place:
  0.1 m or 0.1 rad a scan), scans ray-cast in the map rasterised at 5 cm (``--scans grid``: the
  grid AMCL is given, "a clean simulated grid") or in the vector map with 1 cm range noise
  (``--scans vector``); odometry drawn from the true increments with the odometry motion model
  (Thrun et al., Probabilistic Robotics, Sec. 5.4; α1…α4 = ``--alpha``).
* ``intel``, ``csail``, ``aces``: the SLAM-corrected logs in time order on ``data/maps/real-*.yaml``
  (Intel: 910 scans, 0.67 m median between scans); the logs' odometry columns are the corrected
  poses, so the odometry is drawn from the corrected increments with the same model.

Prints one markdown row per (sequence, tracker): scans, share within 10 cm / 2°, median position
and heading error, CPU ms per scan (median, mean) and per filter update. Usage::

    OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 .venv/bin/python scripts/amcl_track.py sim intel
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def odometry_increments(truth: np.ndarray, alpha: float, rng: np.random.Generator) -> list:
    """Noisy odometry increments (robot frame of the previous scan) from true poses ``(N, 3)``:
    each true increment as (rot1, trans, rot2), each part perturbed with the odometry motion
    model's variances (α1 rot² + α2 trans², α3 trans² + α4 (rot1² + rot2²), …), α1…α4 = ``alpha``."""
    from tfloc.core.pose import Pose, wrap_angle

    out = [Pose(0.0, 0.0, 0.0)]
    for a, b in zip(truth[:-1], truth[1:], strict=True):
        dx, dy = b[0] - a[0], b[1] - a[1]
        trans = math.hypot(dx, dy)
        rot1 = float(wrap_angle(math.atan2(dy, dx) - a[2])) if trans > 1e-6 else 0.0
        rot2 = float(wrap_angle(b[2] - a[2] - rot1))
        r1 = rot1 + rng.normal(0.0, math.sqrt(alpha * rot1 ** 2 + alpha * trans ** 2))
        t = trans + rng.normal(0.0, math.sqrt(alpha * trans ** 2 + alpha * (rot1 ** 2 + rot2 ** 2)))
        r2 = rot2 + rng.normal(0.0, math.sqrt(alpha * rot2 ** 2 + alpha * trans ** 2))
        out.append(Pose(t * math.cos(r1), t * math.sin(r1), float(wrap_angle(r1 + r2))))
    return out


def office_route() -> np.ndarray:
    """True poses ``(N, 3)`` of the office-1 route: straight legs at 0.1 m a scan, turns in place
    at 0.1 rad a scan."""
    waypoints = [(1.0, 7.5), (6.0, 7.5), (6.0, 3.0), (6.0, 7.5), (13.5, 7.5), (13.5, 11.5), (13.5, 7.5),
                 (18.5, 7.5), (18.5, 3.5), (18.5, 7.5), (9.0, 7.5)]
    poses = [(1.0, 7.5, 0.0)]
    for (x0, y0), (x1, y1) in zip(waypoints[:-1], waypoints[1:], strict=True):
        heading = math.atan2(y1 - y0, x1 - x0)
        turn = math.remainder(heading - poses[-1][2], 2 * math.pi)
        if abs(abs(turn) - math.pi) < 1e-9:
            turn = math.pi  # a U-turn: to the left
        n = math.ceil(abs(turn) / 0.1)
        th0 = poses[-1][2]
        poses += [(x0, y0, math.remainder(th0 + turn * (k + 1) / n, 2 * math.pi)) for k in range(n)]
        length = math.hypot(x1 - x0, y1 - y0)
        n = round(length / 0.1)
        poses += [(x0 + (x1 - x0) * (k + 1) / n, y0 + (y1 - y0) * (k + 1) / n, heading) for k in range(n)]
    return np.array(poses)


class DeadReckoning:
    """The prediction alone: the starting pose composed with the odometry (the floor)."""

    name = "odometry"

    def start(self, map, laser, pose) -> None:  # noqa: A002, ANN001
        self.pose = pose

    def step(self, ranges, odom_delta, stamp):  # noqa: ANN001, ANN201
        from tfloc.core.problem import Estimate

        self.pose = self.pose.compose(odom_delta)
        return Estimate(self.pose, True)


def run(tracker, map_, laser, ranges: np.ndarray, odom: list, truth: np.ndarray) -> dict:
    """Track one sequence; errors and CPU seconds per scan."""
    from tfloc.core.pose import Pose, angdiff

    tracker.start(map_, laser, Pose.from_array(truth[0]))
    err, derr, cpu, updated = [], [], [], []
    for k in range(len(truth)):
        t0 = time.process_time()
        est = tracker.step(ranges[k], odom[k], 0.2 * k)
        cpu.append(time.process_time() - t0)
        err.append(math.hypot(est.pose.x - truth[k, 0], est.pose.y - truth[k, 1]))
        derr.append(abs(math.degrees(float(angdiff(est.pose.theta, truth[k, 2])))))
        updated.append(bool(est.info.get("updated", True)))
    return {"err": np.array(err), "derr": np.array(derr), "cpu": np.array(cpu), "updated": np.array(updated)}


def row(seq: str, name: str, r: dict) -> str:
    ok = (r["err"] <= 0.10) & (r["derr"] <= 2.0)
    upd = r["cpu"][r["updated"]]
    return (f"| {seq} | {name} | {len(ok)} | {100 * ok.mean():.1f} | {100 * (r['err'] <= 0.10).mean():.1f} | "
            f"{100 * np.median(r['err']):.1f} | "
            f"{np.median(r['derr']):.2f} | {100 * r['err'].max():.0f} | {1e3 * np.median(r['cpu']):.2f} | "
            f"{1e3 * r['cpu'].mean():.2f} | {int(r['updated'].sum())} | {1e3 * np.median(upd):.1f} |")


def sequences(which: list[str], scans: str, alpha: float, seed: int):
    from tfloc.core.laser import LaserSpec

    rng = np.random.default_rng(seed)
    if "sim" in which:
        from tfloc.baselines.amcl import amcl_grid

        from tfloc.io.geojson import read_vector_map

        vmap = read_vector_map(ROOT / "data" / "maps" / "office-1.geojson")
        truth = office_route()
        assert vmap.is_free(truth[:, :2], 0.2).all(), "the route leaves the free space"
        laser = LaserSpec.lms200()
        if scans == "grid":
            ranges = amcl_grid(vmap).raycast(truth, laser)
        else:
            ranges = vmap.raycast(truth, laser)
            ranges = ranges + rng.normal(0.0, 0.01, ranges.shape)
        yield f"office-1 route ({scans} scans)", vmap, laser, ranges, odometry_increments(truth, alpha, rng), truth
    from tfloc.datasets import real

    logs = {"intel": ("intel/intel-corrected.log.gz", real.INTEL_LASER, real.NO_RETURN_M),
            "csail": ("mit-csail/csail-corrected.log.gz", real.CSAIL_LASER, real.NO_RETURN_M),
            "aces": ("aces/aces-corrected.log.gz", real.ACES_LASER, real.ACES_NO_RETURN_M)}
    for name, (path, laser, no_return) in logs.items():
        if name not in which:
            continue
        from tfloc.io.carmen import read_carmen
        from tfloc.io.rosmap import read_ros_map

        recs = real.front_scans(read_carmen(ROOT / "data" / "real" / path), laser)
        truth = np.array([r.pose.as_array() for r in recs])
        ranges = np.vstack([real.clean_ranges(r.ranges, no_return) for r in recs])
        grid = read_ros_map(ROOT / "data" / "maps" / f"real-{name}.yaml")
        yield f"{name} (corrected, time order)", grid, laser, ranges, odometry_increments(truth, alpha, rng), truth


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("which", nargs="+", choices=("sim", "intel", "csail", "aces"))
    ap.add_argument("--scans", choices=("grid", "vector"), default="grid")
    ap.add_argument("--alpha", type=float, default=0.05, help="odometry noise α1…α4 (default 0.05)")
    ap.add_argument("--seed", type=int, default=20261201)
    ap.add_argument("--trackers", default="odometry,amcl,tf-plus")
    ap.add_argument("--param", action="append", default=[], help="amcl KEY=VALUE (numbers)")
    ap.add_argument("--label", default="amcl", help="the amcl row's label")
    args = ap.parse_args(argv)
    from tfloc.core.matcher import get_matcher
    from tfloc.core.tracker import as_tracker
    from tfloc.harness.threads import limit_threads

    limit_threads(1)
    params = {k: (float(v) if "." in v or "e" in v else int(v)) for k, v in (p.split("=", 1) for p in args.param)}
    print("| sequence | tracker | scans | ≤ 10 cm & 2° % | ≤ 10 cm % | median cm | median ° | max cm | "
          "CPU ms/scan median | mean | updates | CPU ms/update median |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for seq, map_, laser, ranges, odom, truth in sequences(args.which, args.scans, args.alpha, args.seed):
        for name in args.trackers.split(","):
            if name == "odometry":
                tracker = DeadReckoning()
            else:
                tracker = as_tracker(get_matcher(name, **(params if name == "amcl" else {})))
            label = args.label if name == "amcl" else name
            print(row(seq, label, run(tracker, map_, laser, ranges, odom, truth)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
