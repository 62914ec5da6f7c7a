"""Sparse real sequences: every corrected scan of the Intel, MIT CSAIL and ACES logs, simulated odometry.

Each ``real-<log>-sequence`` holds every front-laser scan of the SLAM-corrected log in file order
(a median of every 4th (CSAIL), 11th (ACES) or 18th (Intel) scan of the
original log), truth = the corrected pose, the robot starting at the
first corrected pose, on the same grid map as the log's scan-to-map dataset
(``data/maps/real-*.yaml``). Condition ``real-sparse``: "every corrected scan, simulated
odometry". The logs' scans at their native rate with the robot's raw odometry are
:mod:`tfloc.datasets.real_native` (``real-<log>-native``).

**Odometry.** Simulated: drawn from the corrected increments with the odometry motion model
(:mod:`tfloc.datasets.motion`), all α = :data:`ALPHA` (the simulated sequences' ``low`` level),
on the corrected trajectory cut into odometry steps of at most 0.1 m and 3°
(:func:`~tfloc.datasets.motion.densify`: odometry runs at its own rate, not at the laser's),
seeded per log. (The corrected logs' FLASER odometry fields hold the corrected pose, and their
timed ODOM lines are raw odometry re-anchored at every corrected pose: data/real/PROVENANCE.md.)

**Stamps.** The logs' ``ipc_timestamp`` where it increases strictly along the file (ACES);
Intel (4 steps backwards) and CSAIL (corrected stamps spread over a constant 10 000 s with 404
repeats) get the scan's index in seconds instead, said in the description.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tfloc.core.pose import Pose
from tfloc.io.carmen import read_carmen
from tfloc.io.scenario import SEQUENCE, Scan, write_scenario

from .motion import OdometryNoise, densify, draw_odometry
from .real import (
    REAL_LOGS,
    clean_ranges,
    front_scans,
)

#: the α's of the drawn odometry (all four)
ALPHA = 0.05
SEQ_SEED = 20091201

#: the condition of these sequences (their sequence set in reports)
CONDITION = {"name": "real-sparse", "label": "every corrected scan, simulated odometry"}

#: each bundled log (:data:`tfloc.datasets.real.REAL_LOGS`) with its title in the descriptions
TITLES = {"intel": "Intel Research Lab", "csail": "MIT CSAIL", "aces": "ACES building, UT Austin"}
LOGS = tuple((*log, TITLES[log[0]]) for log in REAL_LOGS)


def sequence_scans(log_path: Path, laser, no_return: float, rng: np.random.Generator,
                   noise: OdometryNoise) -> tuple[list[Scan], bool]:
    """The scans of a corrected log as a sequence; whether the log's own stamps were kept."""
    recs = front_scans(read_carmen(log_path), laser)
    P = np.array([s.pose.as_array() for s in recs])
    t = np.array([s.timestamp for s in recs])
    own = bool(np.all(np.diff(t) > 0))
    stamps = t if own else np.arange(len(recs), dtype=float)
    dense, at = densify(P)
    odom = draw_odometry(dense, noise, rng)[0][at]
    rows = [Scan(f"s{k:04d}", "real", clean_ranges(r.ranges, no_return),
                 Pose.from_array(P[0]) if k == 0 else None, Pose.from_array(P[k]),
                 stamp=float(stamps[k]), odom=Pose.from_array(odom[k]))
            for k, r in enumerate(recs)]
    return rows, own


def build_sequences(real: Path, out: Path, seed: int = SEQ_SEED) -> list[Path]:
    """(Re)build ``out/scenarios/real-<log>-sequence`` on the maps ``out/maps/real-<log>.yaml``
    (written by :func:`tfloc.datasets.real.build_all`). Each log draws from its own child seed."""
    real, out = Path(real), Path(out)
    noise = OdometryNoise(ALPHA, ALPHA, ALPHA, ALPHA)
    made = []
    for (key, rel, laser, no_return, title), ss in zip(LOGS, np.random.SeedSequence(seed).spawn(len(LOGS)),
                                                        strict=True):
        rows, own = sequence_scans(real / rel, laser, no_return, np.random.default_rng(ss), noise)
        P = np.array([r.true.as_array() for r in rows])
        steps = np.hypot(*np.diff(P[:, :2], axis=0).T)
        turns = np.degrees(np.abs(np.angle(np.exp(1j * np.diff(P[:, 2])))))
        name = f"real-{key}-sequence"
        made.append(write_scenario(
            out / "scenarios" / name, name, out / "maps" / f"real-{key}.yaml", laser, rows,
            description=(
                f"Every corrected scan, simulated odometry: tracking on the {title} corrected log, all "
                f"{len(rows)} front-laser scans in file order ({steps.sum():.0f} m; median "
                f"{np.median(steps):.2f} m, max {steps.max():.2f} m and max {turns.max():.0f} deg between "
                "scans), true = corrected pose (pseudo ground truth), start = the first corrected pose, "
                "map = the scan-to-map dataset's grid. odom_* is simulated: drawn from the corrected "
                "increments by the odometry motion model (Probabilistic Robotics Table 5.6) on steps of at "
                f"most 0.1 m and 3 deg (odometry at its own rate), alphas {ALPHA:g}/{ALPHA:g}/{ALPHA:g}/"
                f"{ALPHA:g}, seed {seed} child {int(ss.spawn_key[-1])}. (The log's scans at their native "
                f"rate with the robot's raw odometry: real-{key}-native.) "
                + ("stamp = the log's ipc_timestamp." if own else
                   "stamp = the scan's index in seconds (the log's stamps do not increase).")),
            mode=SEQUENCE,
            condition={**CONDITION, "odom_noise": "drawn", "alphas": [ALPHA] * 4,
                       "slip": False, "people": False},
            generator={"command": "tfloc real-data", "seed": seed, "child": int(ss.spawn_key[-1])},
            source={"files": [f"data/real/{rel}"], "provenance": "data/real/*/PROVENANCE.md"}))
    return made
