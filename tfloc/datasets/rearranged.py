"""A second changed world: the crowded office as mapped on a busy day, scanned after it changed.

The map is the crowded office (``office-3``: the furnished office with the people, chairs and
boxes that stood there when it was mapped). Each scan sees the same building later, in a world of
its own (seeded):

* **doors**: each doorway of the map (a 0.9 m gap between two collinear walls) stays open as
  mapped, is closed by a 4 cm door leaf, or is ajar (the leaf hinged at one jamb, 20–90° open
  to one side);
* **moved**: each movable object of the map (what ``office-3`` adds to ``office-2``) is gone,
  moved 0.2–1.0 m and turned up to 45°, or left where it was;
* **carts**: carts (0.5 × 0.9 m) parked with their long side along a wall the laser sees, 5–30 cm
  from it, and people walking in free space, seen at laser height as two legs (12 cm discs
  15–35 cm apart);
* **months**: all three at once.

The first generator (:mod:`tfloc.datasets.clutter`) puts discs and squares in open space until a
share of the beams is occluded, on a map without movable objects. Here objects stand against
walls (a cart looks like a wall 5–30 cm closer), doorways close (a room looks like a dead end),
and the map holds objects the world has lost or moved: a held-out test for ``tf-plus``'s
changed-world configuration, which was chosen on the first generator's scans
(``docs/robustness.md``). Every object keeps ``robot_clearance_m`` from the laser and ``gap_m``
from the rest of the world; one that does not fit is skipped (its draws still taken, so a
scan's world depends only on its own seed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely
from shapely import affinity
from shapely.geometry import Point, Polygon, box

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.errors import ConfigError
from tfloc.io.geojson import read_vector_map
from tfloc.io.scenario import Scan, write_scenario
from tfloc.maps.vector import VectorMap

from .protocol import strata
from .synthetic import BundleSpec, sample_pose_pair

#: Scans per offset cell of every dataset (9 × 60 = 540).
PER_CELL = 60
#: The seed sequence key of these datasets (``[seed, SEED_KEY]``).
SEED_KEY = 26
DOOR_WIDTH_M = 0.9


@dataclass(frozen=True)
class RearrangeSpec:
    """What changes between the map and a scan's world (metres, radians, probabilities).

    Attributes:
        doors: redraw every doorway's state (open, closed, ajar; ``door_probs``).
        moved: move or remove the map's movable objects (``gone_prob``, ``moved_prob``).
        carts: carts drawn per scan along the walls in view (each kept if it fits).
        people: people (two legs) drawn per scan in free space in view.
        view_m: carts and people stand within this distance of the laser, in its field of view.
        robot_clearance_m: least distance of any changed object from the laser.
        gap_m: least distance of a new or moved object from the rest of the world.
    """

    doors: bool = False
    moved: bool = False
    carts: int = 0
    people: int = 0
    door_probs: tuple[float, float, float] = (1 / 3, 1 / 3, 1 / 3)  #: open, closed, ajar
    door_leaf_m: float = 0.04  #: leaf thickness
    ajar_rad: tuple[float, float] = (math.radians(20.0), math.radians(90.0))
    gone_prob: float = 0.4
    moved_prob: float = 0.4
    move_m: tuple[float, float] = (0.2, 1.0)
    turn_rad: float = math.radians(45.0)
    cart_m: tuple[float, float] = (0.5, 0.9)  #: cart width × length
    cart_gap_m: tuple[float, float] = (0.05, 0.3)
    leg_diameter_m: float = 0.12
    leg_gap_m: tuple[float, float] = (0.15, 0.35)
    view_m: float = 6.0
    robot_clearance_m: float = 0.5
    gap_m: float = 0.05

    def __post_init__(self) -> None:
        if self.carts < 0 or self.people < 0 or abs(sum(self.door_probs) - 1.0) > 1e-9:
            raise ConfigError("carts and people must be ≥ 0 and door_probs must sum to 1")
        if not 0.0 <= self.gone_prob + self.moved_prob <= 1.0:
            raise ConfigError("gone_prob + moved_prob must lie in [0, 1]")


#: The datasets: name → (style, what changes).
STYLES = {
    "changed-doors": ("doors", RearrangeSpec(doors=True)),
    "changed-moved": ("moved", RearrangeSpec(moved=True)),
    "changed-carts": ("carts", RearrangeSpec(carts=3, people=3)),
    "changed-months": ("months", RearrangeSpec(doors=True, moved=True, carts=3, people=3)),
}


def doorways(m: VectorMap, width: float = DOOR_WIDTH_M) -> list[tuple[np.ndarray, np.ndarray]]:
    """The map's doorways: pairs of jambs ``(p, q)`` (metres), the ends of two wall pieces that
    lie ``width`` apart along the walls' common line, in a fixed order."""
    ends = []
    for g in m.walls:
        for part in shapely.get_parts(g):
            xy = np.asarray(part.coords)
            for a, b in ((xy[0], xy[1]), (xy[-1], xy[-2])):
                ends.append((a, (a - b) / np.hypot(*(a - b))))   # an end, pointing out of its wall
    out = []
    for i, (p, u) in enumerate(ends):
        for q, w in ends[i + 1:]:
            d = q - p
            if (abs(np.hypot(*d) - width) < 1e-6 and abs(u @ d - width) < 1e-6
                    and abs(w @ d + width) < 1e-6):
                out.append((p, q))
    return out


def movables(crowded: VectorMap, furnished: VectorMap) -> list[Polygon]:
    """The crowded map's obstacles the furnished one lacks (people, chairs, boxes), in order."""
    static = {g.wkb for g in furnished.obstacles}
    return [g for g in crowded.obstacles if g.wkb not in static]


def _leaf(p: np.ndarray, q: np.ndarray, angle: float, thickness: float) -> Polygon:
    """A door leaf from the jamb ``p`` towards ``q``, turned by ``angle`` (radians) about ``p``."""
    d = q - p
    leaf = box(0.0, -thickness / 2, float(np.hypot(*d)) - 0.02, thickness / 2)
    heading = math.atan2(d[1], d[0]) + angle
    return affinity.translate(affinity.rotate(leaf, heading, origin=(0, 0), use_radians=True),
                              float(p[0]), float(p[1]))


class _World:
    """The geometry of one scan's world while it is drawn: what is fixed and what was added."""

    def __init__(self, static: VectorMap, kept: list, pose: Pose, spec: RearrangeSpec) -> None:
        self.static, self.spec = static, spec
        self.robot = Point(pose.x, pose.y)
        self.solid = [*static.walls, *static.obstacles, *kept, shapely.boundary(static.outline)]
        self.added: list = []

    def fits(self, obj: Polygon) -> bool:
        """Whether ``obj`` lies inside the building, ``gap_m`` from the world and
        ``robot_clearance_m`` from the laser."""
        return (self.static.outline.contains(obj) and obj.distance(self.robot) >= self.spec.robot_clearance_m
                and float(shapely.distance(np.asarray(self.solid, dtype=object), obj).min()) >= self.spec.gap_m)

    def add(self, obj: Polygon) -> None:
        self.added.append(obj)
        self.solid.append(obj)


def _move(obj: Polygon, spec: RearrangeSpec, rng: np.random.Generator) -> Polygon:
    d, phi, turn = rng.uniform(*spec.move_m), rng.uniform(-math.pi, math.pi), rng.uniform(-1, 1) * spec.turn_rad
    c = obj.centroid
    moved = affinity.rotate(obj, turn, origin=c, use_radians=True)
    return affinity.translate(moved, d * math.cos(phi), d * math.sin(phi))


def _cart(world: _World, pose: Pose, laser: LaserSpec, clean: np.ndarray,
          rng: np.random.Generator) -> Polygon | None:
    """A cart parked along the wall a random beam hits (``None`` if that beam hits nothing within
    ``view_m`` or the wall's direction is not found)."""
    spec = world.spec
    beam, gap, along = int(rng.integers(laser.n_beams)), rng.uniform(*spec.cart_gap_m), rng.uniform(-0.3, 0.3)
    r = float(clean[beam])
    if not r < spec.view_m:
        return None
    a = pose.theta + laser.angles[beam]
    hit = np.array([pose.x + r * math.cos(a), pose.y + r * math.sin(a)])
    segs = world.static.segments
    ab = segs[:, 2:] - segs[:, :2]
    t = np.clip(np.einsum("ij,ij->i", hit - segs[:, :2], ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
    near = segs[:, :2] + t[:, None] * ab
    s = int(np.argmin(np.hypot(*(near - hit).T)))
    u = ab[s] / np.hypot(*ab[s])                       # along the wall
    n = np.array([-u[1], u[0]])
    if n @ (np.array([pose.x, pose.y]) - hit) < 0:      # towards the laser
        n = -n
    width, length = spec.cart_m
    centre = hit + n * (gap + width / 2) + u * along
    heading = math.atan2(u[1], u[0])
    cart = affinity.rotate(box(-length / 2, -width / 2, length / 2, width / 2), heading,
                           origin=(0, 0), use_radians=True)
    return affinity.translate(cart, float(centre[0]), float(centre[1]))


def _person(world: _World, pose: Pose, laser: LaserSpec, clean: np.ndarray,
            rng: np.random.Generator) -> Polygon | None:
    """Two legs on a random beam, in front of its clean return."""
    spec = world.spec
    beam, u, gap, turn = int(rng.integers(laser.n_beams)), rng.random(), rng.uniform(*spec.leg_gap_m), rng.uniform(0, math.pi)
    far = min(spec.view_m, float(clean[beam]) - 0.5)
    if far <= spec.robot_clearance_m + 0.3:
        return None
    d = spec.robot_clearance_m + 0.3 + u * (far - spec.robot_clearance_m - 0.3)
    a = pose.theta + laser.angles[beam]
    cx, cy = pose.x + d * math.cos(a), pose.y + d * math.sin(a)
    half = 0.5 * (gap + spec.leg_diameter_m)
    legs = [Point(cx + s * half * math.cos(turn), cy + s * half * math.sin(turn)).buffer(
        spec.leg_diameter_m / 2, quad_segs=4) for s in (-1.0, 1.0)]
    return shapely.union_all(legs)


def rearrange(crowded: VectorMap, static: VectorMap, items: list[Polygon],
              doors: list[tuple[np.ndarray, np.ndarray]], pose: Pose, laser: LaserSpec,
              spec: RearrangeSpec, rng: np.random.Generator) -> tuple[VectorMap, dict]:
    """The world one scan at ``pose`` sees: the map ``crowded`` (``static`` without its movable
    ``items``) changed as ``spec`` says, and counts of what changed. The draws per item, door,
    cart and person are taken whether or not they are used."""
    kept, moving = list(items), []
    counts = {"gone": 0, "moved": 0, "closed": 0, "ajar": 0, "carts": 0, "people": 0}
    if spec.moved:
        kept = []
        for obj in items:
            u, moved = rng.random(), _move(obj, spec, rng)
            if u < spec.gone_prob:
                counts["gone"] += 1
            elif u < spec.gone_prob + spec.moved_prob:
                moving.append((obj, moved))
            else:
                kept.append(obj)
    world = _World(static, kept, pose, spec)
    for obj, moved in moving:                      # a move that does not fit leaves it in place
        if world.fits(moved):
            world.add(moved)
            counts["moved"] += 1
        else:
            world.add(obj)
    if spec.doors:
        for p, q in doors:
            u, side, swing, hinge = rng.random(), rng.random() < 0.5, rng.uniform(*spec.ajar_rad), rng.random() < 0.5
            a, b = (p, q) if hinge else (q, p)
            if u < spec.door_probs[0]:
                continue
            closed = u < spec.door_probs[0] + spec.door_probs[1]
            leaf = _leaf(a, b, 0.0 if closed else (swing if side else -swing), spec.door_leaf_m)
            if leaf.distance(world.robot) < spec.robot_clearance_m + 0.3:
                continue
            world.add(leaf)                         # a leaf touches its jamb: no gap test
            counts["closed" if closed else "ajar"] += 1
    clean = crowded.raycast(pose, laser)
    for draw, n, key in ((_cart, spec.carts, "carts"), (_person, spec.people, "people")):
        for _ in range(n):
            obj = draw(world, pose, laser, clean, rng)
            if obj is not None and world.fits(obj):
                world.add(obj)
                counts[key] += 1
    return VectorMap(walls=static.walls, obstacles=(*static.obstacles, *kept, *world.added),
                     outline=static.outline, name="world"), counts


def generate_rearranged(out: str | Path, spec: BundleSpec | None = None, per_cell: int = PER_CELL,
                        log=None) -> list[Path]:
    """Write ``out/scenarios/changed-{doors,moved,carts,months}`` (the maps
    ``out/maps/office-{2,3}.geojson`` must exist: :func:`tfloc.datasets.synthetic.generate_bundle`).
    All four share the true and initial poses (the protocol's 3 × 3 offset cells, poses free in
    the crowded map) and the range noise draws; each scan's world is drawn from its own seed."""
    out, spec = Path(out), spec or BundleSpec()
    map_path = out / "maps" / "office-3.geojson"
    crowded, furnished = read_vector_map(map_path), read_vector_map(out / "maps" / "office-2.geojson")
    items, doors = movables(crowded, furnished), doorways(crowded)
    moving = {g.wkb for g in items}
    static = VectorMap(walls=crowded.walls, obstacles=tuple(g for g in crowded.obstacles if g.wkb not in moving),
                       outline=crowded.outline)
    ss_poses, ss_noise, *ss_styles = np.random.SeedSequence([spec.seed, SEED_KEY]).spawn(2 + len(STYLES))
    rng = np.random.default_rng(ss_poses)
    cells = [(c, k) for c in strata() for k in range(per_cell)]
    pairs = [sample_pose_pair(crowded, c, rng, spec.clearance_m) for c, _ in cells]
    dirs = []
    for (name, (style, rspec)), ss in zip(STYLES.items(), ss_styles, strict=True):
        noise_rng = np.random.default_rng(ss_noise)     # the same noise draws for every dataset
        worlds = ss.spawn(len(cells))
        scans, changed, totals = [], [], dict.fromkeys(("gone", "moved", "closed", "ajar", "carts", "people"), 0)
        for ((cell, k), (true, init)), ws in zip(zip(cells, pairs, strict=True), worlds, strict=True):
            world, counts = rearrange(crowded, static, items, doors, true, spec.laser, rspec,
                                      np.random.default_rng(ws))
            ideal = world.raycast(true, spec.laser)
            changed.append(float(np.mean(np.abs(np.minimum(ideal, 20.0) - np.minimum(
                crowded.raycast(true, spec.laser), 20.0)) > 0.05)))
            for key, v in counts.items():
                totals[key] += v
            scans.append(Scan(f"{cell.label}-{k:03d}", cell.label, spec.noise.apply(ideal, spec.laser, noise_rng),
                              init, true))
        q = np.percentile(changed, [0, 50, 100])
        desc = (f"A changed world on the crowded office as mapped (map office-3): {_what(rspec)}; "
                f"{len(scans)} scans, poses shared by changed-doors/moved/carts/months; LMS200, sigma "
                f"{spec.noise.sigma_m:g} m. Beams changed (by more than 5 cm) per scan: min {q[0]:.1%}, "
                f"median {q[1]:.1%}, max {q[2]:.1%}.")
        root = out / "scenarios" / name
        write_scenario(root, name, map_path, spec.laser, scans, description=desc,
                       axis={"log": "office-crowded-sim", "style": style},
                       generator={"command": "tfloc generate", "module": "tfloc.datasets.rearranged",
                                  "seed": spec.seed, "seed_key": SEED_KEY, "per_cell": per_cell,
                                  "clearance_m": spec.clearance_m, "doors": rspec.doors,
                                  "moved": rspec.moved, "carts": rspec.carts, "people": rspec.people,
                                  "changes": totals,
                                  "changed_beams": {"min": round(float(q[0]), 4),
                                                    "median": round(float(q[1]), 4),
                                                    "max": round(float(q[2]), 4)},
                                  "noise": {"sigma_m": spec.noise.sigma_m}})
        dirs.append(root)
        if log:
            log(f"{root}: {len(scans)} scans on {map_path.name}")
    return dirs


def _what(spec: RearrangeSpec) -> str:
    parts = []
    if spec.doors:
        parts.append("doorways open, closed or ajar")
    if spec.moved:
        parts.append("the map's people, chairs and boxes gone, moved or left")
    if spec.carts or spec.people:
        parts.append(f"up to {spec.carts} carts along the walls and {spec.people} people (legs) in view")
    return ", ".join(parts)
