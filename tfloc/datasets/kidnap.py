"""Kidnapped-robot sequences: the simulated office routes, with the robot carried off now and then.

A kidnapped sequence is a route of :mod:`tfloc.datasets.sequences` driven at 10 Hz with low
odometry noise (condition ``easy``), except that at a few **kidnap scans** the robot is moved
5–20 m to another pose of the same route and turned (its heading differs by at least 30°), and
drives the route on from there. The odometry does not see the jump: its increment at a kidnap
scan is the small motion the robot would have made had it not been moved (the route's next step
from where it was), drawn through the same odometry motion model as every other increment.

``scenario.json`` records the events (``"kidnaps"``: the scan ids of the kidnap scans, the first
scan at the new pose) and their sizes (``"kidnap_events"``: jump in metres, turn in degrees), so
that metrics find them without a tracker ever reading the truth; ``"set"`` is ``kidnap`` (the
evaluation sequences) or ``kidnap-dev`` (the development sequence the recovery rule was chosen on,
``docs/kidnap.md``). Each dataset draws from its own child of :data:`KIDNAP_SEED`, so the
bundle is reproducible bit for bit and no other dataset's bytes depend on it. Units: metres,
radians, seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tfloc.core.pose import Pose, angdiff
from tfloc.io.geojson import read_vector_map
from tfloc.io.scenario import SEQUENCE, Scan, write_scenario

from .motion import draw_odometry
from .routes import ROUTES, drive, plan_route
from .sequences import LOW, SimSpec

KIDNAP_SEED = 20261224


@dataclass(frozen=True)
class KidnapSpec:
    """One kidnapped sequence: route on an office level, length (scans), kidnap events, its set."""

    name: str
    route: str
    level: int
    scans: int = 560
    events: int = 4
    set: str = "kidnap"


@dataclass(frozen=True)
class Kidnapping:
    """How far and how much turned a kidnap takes the robot (metres, degrees), and the fewest
    scans between two events (and before the first, after the last)."""

    min_m: float = 5.0
    max_m: float = 20.0
    min_turn_deg: float = 30.0
    min_gap: int = 90

    def to_dict(self) -> dict:
        return {"min_m": self.min_m, "max_m": self.max_m, "min_turn_deg": self.min_turn_deg,
                "min_gap_scans": self.min_gap}


#: the evaluation sequences (route a/b/c on office-1/2/3, as the other sequences) and the
#: development one (route c on office-1: another route, another floor than its evaluation twin)
KIDNAP_BUNDLE: tuple[KidnapSpec, ...] = (
    KidnapSpec("seq-kidnap-a", "a", 1), KidnapSpec("seq-kidnap-b", "b", 2),
    KidnapSpec("seq-kidnap-c", "c", 3), KidnapSpec("seq-kidnap-dev", "c", 1, set="kidnap-dev"),
)


def kidnap_indices(route: np.ndarray, n_scans: int, n_events: int, kid: Kidnapping,
                   rng: np.random.Generator) -> tuple[np.ndarray, list[int]]:
    """Which sample of the driven ``route`` ``(N, 3)`` the robot is at for each scan, and the kidnap
    scans. Events are spread evenly (± a quarter of the spacing, at least ``kid.min_gap`` apart);
    each target is a uniformly drawn route sample ``kid.min_m``–``max_m`` from the robot's pose,
    turned by at least ``kid.min_turn_deg``, with enough route left to drive on to the next event."""
    spacing = n_scans / (n_events + 1)
    events = []
    for e in range(1, n_events + 1):
        lo = max(int(e * spacing - spacing / 4), (events[-1] if events else 0) + kid.min_gap)
        hi = max(lo, min(int(e * spacing + spacing / 4), n_scans - (n_events - e + 1) * kid.min_gap))
        events.append(int(rng.integers(lo, hi + 1)))
    if events[-1] > n_scans - kid.min_gap:
        raise ValueError(f"{n_events} kidnaps do not fit {n_scans} scans {kid.min_gap} apart")
    n = len(route)
    idx = np.empty(n_scans, dtype=int)
    idx[0] = 0
    bounds = [*events, n_scans]
    for k in range(1, n_scans):
        if k in events:
            here = route[idx[k - 1]]
            room = bounds[bounds.index(k) + 1] - k
            cand = np.arange(n)
            d = np.hypot(route[:, 0] - here[0], route[:, 1] - here[1])
            turn = np.degrees(np.abs(angdiff(route[:, 2], here[2])))
            ok = (d >= kid.min_m) & (d <= kid.max_m) & (turn >= kid.min_turn_deg) & (cand + room < n)
            if not ok.any():
                raise ValueError(f"no kidnap target {kid.min_m}-{kid.max_m} m away from {here}")
            idx[k] = int(rng.choice(cand[ok]))
        else:
            idx[k] = (idx[k - 1] + 1) % n
    return idx, events


def wheel_poses(route: np.ndarray, idx: np.ndarray, events: list[int]) -> np.ndarray:
    """The poses the wheels believe ``(N, 3)``: the true increments composed from the start, except
    at a kidnap scan, whose increment is the route's next step from where the robot was."""
    out = [Pose.from_array(route[idx[0]])]
    for k in range(1, len(idx)):
        a = idx[k - 1]
        b = (a + 1) % len(route) if k in events else idx[k]
        out.append(out[-1].compose(Pose.from_array(route[a]).between(Pose.from_array(route[b]))))
    return np.array([p.as_array() for p in out])


def generate_kidnap_sequences(out: str | Path, spec: SimSpec | None = None, kid: Kidnapping = Kidnapping(),
                              bundle: tuple[KidnapSpec, ...] = KIDNAP_BUNDLE, seed: int = KIDNAP_SEED,
                              log=None) -> list[Path]:
    """Write the kidnapped sequences ``out/scenarios/seq-kidnap-*`` on the office maps under
    ``out/maps`` (written first by :func:`tfloc.datasets.synthetic.generate_bundle`)."""
    out, spec = Path(out), spec or SimSpec()
    dirs = []
    rate_hz = 10.0
    for item, ss in zip(bundle, np.random.SeedSequence(seed).spawn(len(bundle)), strict=True):
        path = out / "maps" / f"office-{item.level}.geojson"
        m = read_vector_map(path)
        _, route = drive(plan_route(m, ROUTES[item.route]), spec.motion, rate_hz)
        ev_ss, odom_ss, scan_ss = ss.spawn(3)
        idx, events = kidnap_indices(route, item.scans, item.events, kid, np.random.default_rng(ev_ss))
        true = route[idx]
        odom, _ = draw_odometry(wheel_poses(route, idx, events), LOW, np.random.default_rng(odom_ss))
        ideal = m.raycast(true, spec.laser)
        rng = np.random.default_rng(scan_ss)
        scans = [Scan(f"k{k:05d}", "kidnap", spec.noise.apply(ideal[k], spec.laser, rng),
                      Pose.from_array(true[0]) if k == 0 else None, Pose.from_array(true[k]),
                      stamp=k / rate_hz, odom=Pose.from_array(odom[k])) for k in range(item.scans)]
        sizes = [{"scan_id": f"k{e:05d}",
                  "jump_m": round(float(np.hypot(*(true[e, :2] - route[(idx[e - 1] + 1) % len(route), :2]))), 3),
                  "turn_deg": round(math.degrees(abs(float(angdiff(true[e, 2], true[e - 1, 2])))), 2)}
                 for e in events]
        root = out / "scenarios" / item.name
        desc = (f"A simulated robot driving route {item.route} through office-{item.level} "
                f"({item.scans} scans at 10 Hz, 1 m/s, turns in place at 30 deg/s; odometry alphas "
                f"{'/'.join(f'{a:g}' for a in LOW.alphas)}), kidnapped {len(events)} times: moved "
                f"{kid.min_m:g}-{kid.max_m:g} m to another pose of the route and turned by at least "
                f"{kid.min_turn_deg:g} deg, unseen by the odometry"
                + (" (development sequence)." if item.set != "kidnap" else "."))
        write_scenario(root, item.name, path, spec.laser, scans, description=desc, mode=SEQUENCE,
                       condition={"name": "kidnap", "rate_hz": rate_hz, "odom_noise": "low",
                                  "alphas": list(LOW.alphas), "slip": False, "people": False},
                       route=item.route, set=item.set, kidnaps=[f"k{e:05d}" for e in events],
                       kidnap_events=sizes,
                       generator={"command": "tfloc generate", "seed": seed,
                                  "child": int(ss.spawn_key[-1]), "kidnapping": kid.to_dict(),
                                  "noise": spec.noise.record()})
        dirs.append(root)
        if log:
            log(f"{root}: {item.scans} scans, kidnaps at {events} on {path.name}")
    return dirs
