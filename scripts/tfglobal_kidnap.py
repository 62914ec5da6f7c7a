"""Kidnapped-robot check of tf-plus with tf-global recovery (tfloc.relocalize.recovery) on
simulated sequences (docs/tf-global.md).

A robot walks through the free space of an office map (0.25 m steps, turning away from walls;
LMS200 scans, σ = 1 cm; odometry increments with 2 % / 0.5° noise). At scans 20 and 45 it is
kidnapped: moved 5–20 m to a random free pose and turned, while the odometry reports an ordinary
step. Reported per event: scans until the estimate is within 10 cm / 2° of the truth again
(≤ 20 required), and false relocalizations (the global answer taken while the estimate was right).

Usage: OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 .venv/bin/python scripts/tfglobal_kidnap.py SET
(SET = dev: office-1/2, seeds 24101–24106; heldout: office-3, seeds 24201–24203) [key=value ...]
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.matcher import get_matcher
from tfloc.core.pose import Pose, angdiff
from tfloc.core.problem import Problem
from tfloc.datasets.noise import NoiseModel
from tfloc.datasets.synthetic import sample_free_pose
from tfloc.harness.threads import limit_threads
from tfloc.io.maps import load_map
from tfloc.relocalize.recovery import RecoveringTracker

ROOT = Path(__file__).resolve().parents[1]
SETS = {"dev": [("office-1", 24101), ("office-1", 24102), ("office-1", 24103),
                ("office-2", 24104), ("office-2", 24105), ("office-2", 24106)],
        "heldout": [("office-3", 24201), ("office-3", 24202), ("office-3", 24203)]}
KIDNAPS = (20, 45)
LENGTH = 70


def walk(m, rng: np.random.Generator) -> tuple[list[Pose], list[Pose]]:
    """True poses and the odometry increments the wheels report (kidnaps not among them)."""
    pose = sample_free_pose(m, rng, 0.5)
    poses, odom = [pose], [Pose()]
    for k in range(1, LENGTH):
        step = Pose(0.25, 0.0, rng.normal(0.0, 0.1))
        for _ in range(50):
            nxt = pose.compose(step)
            ahead = nxt.compose(Pose(0.5, 0.0, 0.0))
            if m.is_free(np.array([nxt.xy, ahead.xy]), 0.3).all():
                break
            step = Pose(0.0, 0.0, rng.uniform(-math.pi, math.pi))
        reported = Pose(step.x * (1 + rng.normal(0, 0.02)), step.y,
                        step.theta + rng.normal(0, math.radians(0.5)))
        if k in KIDNAPS:
            while True:
                nxt = sample_free_pose(m, rng, 0.5)
                if 5.0 <= nxt.distance_to(pose) <= 20.0:
                    break
        pose = nxt
        poses.append(pose)
        odom.append(reported)
    return poses, odom


def ok(a: Pose, b: Pose) -> bool:
    return a.distance_to(b) <= 0.10 and abs(angdiff(a.theta, b.theta)) <= math.radians(2.0)


def main(argv: list[str]) -> None:
    limit_threads(1)
    which = argv[0]
    kv = {k: json.loads(v) for k, _, v in (a.partition("=") for a in argv[1:])}
    laser, noise = LaserSpec.lms200(), NoiseModel()
    tracker = RecoveringTracker(get_matcher("tf-plus"), get_matcher("tf-global"), **kv)
    events = []
    false_reloc = 0
    for name, seed in SETS[which]:
        m = load_map(ROOT / "data" / "maps" / f"{name}.geojson")
        rng = np.random.default_rng(seed)
        poses, odom = walk(m, rng)
        tracker.global_.prepare(Problem(m, laser, m.raycast(poses[0], laser), None))
        tracker.start(m, laser, poses[0])
        right = [True]
        for k in range(1, LENGTH):
            ranges = noise.apply(m.raycast(poses[k], laser), laser, rng)
            was_right = right[-1]
            est = tracker.step(ranges, odom[k], float(k))
            if est.info["relocalized"] and was_right and k not in KIDNAPS:
                false_reloc += 1
            right.append(ok(est.pose, poses[k]))
        for kid in KIDNAPS:
            back = next((k - kid for k in range(kid, LENGTH) if right[k]), None)
            events.append({"map": name, "seed": seed, "kidnap": kid, "scans_to_relocalize": back})
        print(json.dumps({"map": name, "seed": seed, "right": f"{sum(right)}/{LENGTH}",
                          "events": events[-2:]}), flush=True)
    backs = [e["scans_to_relocalize"] for e in events]
    print(json.dumps({"set": which, **kv, "events": len(events),
                      "relocalized_within_20": sum(b is not None and b <= 20 for b in backs),
                      "scans_to_relocalize": backs, "false_relocalizations": false_reloc}))


if __name__ == "__main__":
    main(sys.argv[1:])
