"""Simulated sequence datasets: a robot driving routes through the office floors, scanning.

Each dataset is one route (:mod:`tfloc.datasets.routes`) driven at 1 m/s with turns in place at
30°/s, scanned at ``rate_hz`` by the simulated LMS200 (the paper protocol's noise model,
:class:`~tfloc.datasets.noise.NoiseModel`), with raw odometry drawn from the true increments by
the odometry motion model (:mod:`tfloc.datasets.motion`) on the 10 Hz trajectory whatever
the scan rate (odometry runs at its own rate: a lower scan rate means larger gaps between
scans, not worse odometry). The **condition** of a dataset is a
label in ``scenario.json`` (``"condition": {"name", "rate_hz", "odom_noise", "slip", "people"}``)
and names what makes a robot lose track:

* ``easy``: 10 Hz (0.1 m and 3° between scans), low odometry noise (all α = 0.05);
* ``rate-2hz`` / ``rate-1hz``: 0.5 m and 15° / 1 m and 30° between scans, low noise;
* ``odom-high``: 10 Hz, high odometry noise (all α = 0.2, Nav2 AMCL's defaults);
* ``slip``: 10 Hz, low noise, wheel slip (a 0.3–1 m jump the odometry does not see, 1 % of scans);
* ``people``: 10 Hz, low noise, four people (0.3 m discs, not in the map) walking back and forth
  along the route at 0.8 m/s, 0.35 m to its side, ray-cast into the scans (one within 0.6 m of
  the robot steps aside: it is not drawn);
* ``combined``: all of it at once: 1 Hz, high odometry noise, wheel slip and people (no single
  factor made any matcher lose track often: ``docs/tracking.md``).

Design (all under ``data/scenarios/seq-*``, about 16 MB): ``easy`` and the rate conditions on all
three routes (route a on office-1, b on office-2, c on office-3); the other hard conditions on
route b (office-2) only, so that each compares with ``seq-easy-b`` on the same route and map;
``combined`` on all three routes (appended last: the other datasets keep their seeds);
``seq-quick``: the first 100 scans of ``seq-easy-b`` (``make quick``, the regression guard;
reported as its own set, ``"set": "quick"``, not with the easy sequences it repeats).
Every dataset draws from its own child of one master seed (``SeedSequence.spawn``), in a fixed
order, so the bundle is reproducible bit for bit and adding a dataset at the end changes no other.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.io.geojson import read_vector_map
from tfloc.io.scenario import SEQUENCE, Scan, write_scenario
from tfloc.maps.vector import VectorMap

from .motion import OdometryNoise, Slip, draw_odometry
from .noise import NoiseModel
from .routes import ROUTES, Motion, drive, plan_route

SEQ_SEED = 20261201
LOW, HIGH = OdometryNoise(0.05, 0.05, 0.05, 0.05), OdometryNoise(0.2, 0.2, 0.2, 0.2)
QUICK_SCANS = 100
#: the odometry's rate (Hz): the true trajectory is sampled at this rate, the scans every
#: ``ODOM_RATE_HZ / rate_hz``-th sample
ODOM_RATE_HZ = 10.0


@dataclass(frozen=True)
class People:
    """Unmapped people: ``n`` discs of ``radius_m`` walking back and forth along the route."""

    n: int = 4
    radius_m: float = 0.15
    speed_m_s: float = 0.8
    offset_m: float = 0.35
    hide_within_m: float = 0.6


@dataclass(frozen=True)
class Condition:
    """What the robot faces on a sequence (module notes)."""

    name: str
    rate_hz: float = 10.0
    odom_noise: str = "low"
    slip: bool = False
    people: bool = False

    @property
    def noise(self) -> OdometryNoise:
        return HIGH if self.odom_noise == "high" else LOW

    def to_dict(self) -> dict:
        return {"name": self.name, "rate_hz": self.rate_hz, "odom_noise": self.odom_noise,
                "alphas": list(self.noise.alphas), "slip": self.slip, "people": self.people}


CONDITIONS = {c.name: c for c in (
    Condition("easy"), Condition("rate-2hz", rate_hz=2.0), Condition("rate-1hz", rate_hz=1.0),
    Condition("odom-high", odom_noise="high"), Condition("slip", slip=True),
    Condition("people", people=True),
    Condition("combined", rate_hz=1.0, odom_noise="high", slip=True, people=True))}
ROUTE_LEVEL = {"a": 1, "b": 2, "c": 3}


@dataclass(frozen=True)
class SequenceSpec:
    """One dataset of the bundle: its name, route, condition, (optionally) a scan limit and the
    sequence set it is reported in (default: its condition's)."""

    name: str
    route: str
    condition: str
    limit: int | None = None
    set: str | None = None


BUNDLE: tuple[SequenceSpec, ...] = (
    *(SequenceSpec(f"seq-easy-{r}", r, "easy") for r in "abc"),
    *(SequenceSpec(f"seq-{c}-{r}", r, c) for c in ("rate-2hz", "rate-1hz") for r in "abc"),
    *(SequenceSpec(f"seq-{c}-b", "b", c) for c in ("odom-high", "slip", "people")),
    SequenceSpec("seq-quick", "b", "easy", QUICK_SCANS, set="quick"),
    *(SequenceSpec(f"seq-combined-{r}", r, "combined") for r in "abc"),
)


@dataclass(frozen=True)
class SimSpec:
    """The sensor and motion of every simulated sequence."""

    seed: int = SEQ_SEED
    laser: LaserSpec = LaserSpec.lms200()
    noise: NoiseModel = NoiseModel()
    motion: Motion = Motion()
    slip: Slip = Slip()
    people: People = People()
    bundle: tuple[SequenceSpec, ...] = field(default=BUNDLE)


def _along(verts: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points at arc lengths ``s`` on the polyline ``verts`` and the left normals there."""
    seg = np.diff(verts, axis=0)
    lens = np.hypot(seg[:, 0], seg[:, 1])
    cum = np.concatenate([[0.0], np.cumsum(lens)])
    k = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
    f = ((s - cum[k]) / np.maximum(lens[k], 1e-12))[:, None]
    u = seg[k] / np.maximum(lens[k], 1e-12)[:, None]
    return verts[k] + f * seg[k], np.column_stack([-u[:, 1], u[:, 0]])


def people_at(verts: np.ndarray, t: float, people: People, phase: np.ndarray) -> np.ndarray:
    """Centres ``(n, 2)`` of the people at time ``t`` (s): person i walks back and forth along
    the route from arc fraction ``phase[i]``, on alternating sides."""
    L = float(np.hypot(*np.diff(verts, axis=0).T).sum())
    s = (phase * 2 * L + people.speed_m_s * t) % (2 * L)
    s = np.where(s > L, 2 * L - s, s)
    pts, normal = _along(verts, s)
    side = np.where(np.arange(len(phase)) % 2 == 0, 1.0, -1.0)[:, None]
    return pts + side * people.offset_m * normal


def discs_ranges(pose: np.ndarray, laser: LaserSpec, centres: np.ndarray, radius: float) -> np.ndarray:
    """Range (m) of each beam from ``pose`` to the nearest of the discs, ``inf`` if none is hit."""
    ang = pose[2] + np.asarray(laser.angles, dtype=float)
    d = np.column_stack([np.cos(ang), np.sin(ang)])  # (B, 2)
    rel = centres - pose[:2]  # (P, 2)
    b = d @ rel.T  # (B, P)
    c = (rel ** 2).sum(axis=1) - radius ** 2  # (P,)
    disc = b ** 2 - c
    with np.errstate(invalid="ignore"):
        t = b - np.sqrt(disc)
    t = np.where((disc >= 0) & (t > 0), t, np.inf)
    return t.min(axis=1) if t.shape[1] else np.full(len(ang), np.inf)


def simulate(m: VectorMap, verts: np.ndarray, cond: Condition, spec: SimSpec,
             ss: np.random.SeedSequence, limit: int | None = None) -> tuple[list[Scan], dict]:
    """The scans of one sequence (ids ``k00000``…, group = the condition's name) and a summary."""
    stamps, fine = drive(verts, spec.motion, ODOM_RATE_HZ)
    odom_ss, scan_ss, people_ss = ss.spawn(3)
    odom, slipped = draw_odometry(fine, cond.noise, np.random.default_rng(odom_ss),
                                  spec.slip if cond.slip else None)
    stride = int(round(ODOM_RATE_HZ / cond.rate_hz))
    at = np.arange(0, len(fine), stride)[:limit]
    stamps, true, odom = stamps[at], fine[at], odom[at]
    slipped = np.array([slipped[a + 1:b + 1].any() for a, b in zip(at[:-1], at[1:], strict=True)])
    ideal = m.raycast(true, spec.laser)
    if cond.people:
        phase = np.random.default_rng(people_ss).random(spec.people.n)
        for k, (t, p) in enumerate(zip(stamps, true, strict=True)):
            c = people_at(verts, float(t), spec.people, phase)
            c = c[np.hypot(*(c - p[:2]).T) > spec.people.hide_within_m]
            ideal[k] = np.minimum(ideal[k], discs_ranges(p, spec.laser, c, spec.people.radius_m))
    rng = np.random.default_rng(scan_ss)
    scans = []
    for k in range(len(true)):
        ranges = spec.noise.apply(ideal[k], spec.laser, rng)
        scans.append(Scan(f"k{k:05d}", cond.name, ranges, Pose.from_array(true[0]) if k == 0 else None,
                          Pose.from_array(true[k]), stamp=float(stamps[k]), odom=Pose.from_array(odom[k])))
    steps = np.hypot(*np.diff(true[:, :2], axis=0).T)
    turns = np.degrees(np.abs(np.angle(np.exp(1j * np.diff(true[:, 2])))))
    reckoned = Pose.from_array(true[0]).compose(Pose.from_array(odom[0]).between(Pose.from_array(odom[-1])))
    dr = reckoned.distance_to(Pose.from_array(true[-1]))  # dead reckoning's error at the end
    return scans, {"scans": len(scans), "distance_m": round(float(steps.sum()), 3),
                   "max_step_m": round(float(steps.max(initial=0)), 3),
                   "max_turn_deg": round(float(turns.max(initial=0)), 2),
                   "slip_scans": int(slipped.sum()), "dead_reckoning_end_error_m": round(float(dr), 3)}


def generate_sequences(out: str | Path, spec: SimSpec = SimSpec(), log=None) -> list[Path]:
    """Write the bundle's sequence datasets ``out/scenarios/seq-*`` on the office maps under
    ``out/maps`` (written first by :func:`tfloc.datasets.synthetic.generate_bundle`)."""
    out = Path(out)
    seeds = np.random.SeedSequence(spec.seed).spawn(len(spec.bundle))
    maps: dict[int, tuple[Path, VectorMap]] = {}
    routes: dict[str, np.ndarray] = {}
    dirs = []
    for item, ss in zip(spec.bundle, seeds, strict=True):
        level = ROUTE_LEVEL[item.route]
        if level not in maps:
            path = out / "maps" / f"office-{level}.geojson"
            maps[level] = (path, read_vector_map(path))
        path, m = maps[level]
        if item.route not in routes:
            routes[item.route] = plan_route(m, ROUTES[item.route])
        cond = CONDITIONS[item.condition]
        scans, summary = simulate(m, routes[item.route], cond, spec, ss, item.limit)
        root = out / "scenarios" / item.name
        desc = (f"A simulated robot driving route {item.route} through office-{level} "
                f"({summary['distance_m']:.0f} m, {summary['scans']} scans at {cond.rate_hz:g} Hz, "
                f"1 m/s, turns in place at 30 deg/s), condition {cond.name}; odometry drawn by the "
                "odometry motion model (Probabilistic Robotics Table 5.6), alphas "
                f"{'/'.join(f'{a:g}' for a in cond.noise.alphas)}"
                + (f"; wheel slip: {summary['slip_scans']} unobserved jumps of "
                   f"{spec.slip.min_m:g}-{spec.slip.max_m:g} m" if cond.slip else "")
                + (f"; {spec.people.n} unmapped people (0.3 m discs) walking along the route"
                   if cond.people else "") + ".")
        extra = {} if item.set is None else {"set": item.set}
        write_scenario(root, item.name, path, spec.laser, scans, description=desc, mode=SEQUENCE,
                       condition=cond.to_dict(), route=item.route, **extra,
                       generator={"command": "tfloc generate", "seed": spec.seed,
                                  "child": int(ss.spawn_key[-1]), **summary,
                                  "noise": spec.noise.record()})
        dirs.append(root)
        if log:
            log(f"{root}: {summary['scans']} scans, {summary['distance_m']:.0f} m on {path.name}")
    return dirs
