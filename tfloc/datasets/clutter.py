"""A changed world: unmapped objects in front of the laser, mapped furniture gone.

The map stays the furnished office (``office-2``); the world the scans are simulated in differs:

* **clutter**: people (discs 0.3 m across) and boxes (0.3–0.6 m squares) that are not in the map,
  placed in free space in front of the laser until they occlude a requested share of the beams
  (a beam is occluded when an object shortens its range; beams without a return count too);
* **furniture gone**: the world is the office without its furniture (``office-1``); the map
  still has it.

Objects are drawn one at a time (seeded); one that would push the share past the target by
more than ``tolerance`` is discarded, and drawing stops as soon as the share is within
``tolerance`` of the target.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Polygon

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.errors import ConfigError
from tfloc.maps.vector import VectorMap


@dataclass(frozen=True)
class ClutterSpec:
    """How unmapped objects are drawn (metres; shares in [0, 1]).

    Attributes:
        share: target share of the scan's beams to occlude.
        tolerance: accepted distance of the achieved share from the target.
        person_diameter_m: a person's disc.
        box_side_m: range of a box's side (uniform).
        person_prob: probability that a drawn object is a person (else a box).
        min_dist_m, max_dist_m: distance of an object's centre from the laser.
        gap_m: least distance of an object from the map's geometry and from other objects.
        max_draws: objects drawn at most per scan.
    """

    share: float
    tolerance: float = 0.02
    person_diameter_m: float = 0.3
    box_side_m: tuple[float, float] = (0.3, 0.6)
    person_prob: float = 0.5
    min_dist_m: float = 0.6
    max_dist_m: float = 6.0
    gap_m: float = 0.05
    max_draws: int = 400

    def __post_init__(self) -> None:
        if not (0.0 <= self.share < 1.0 and 0.0 < self.tolerance < 1.0):
            raise ConfigError(f"clutter share must be in [0, 1) and tolerance in (0, 1), got "
                              f"{self.share}, {self.tolerance}")
        if not 0.0 < self.min_dist_m < self.max_dist_m:
            raise ConfigError(f"clutter distances must satisfy 0 < min < max, got {self.min_dist_m}, "
                              f"{self.max_dist_m}")


def _draw_object(spec: ClutterSpec, pose: Pose, laser: LaserSpec, clean: np.ndarray,
                 rng: np.random.Generator) -> Polygon | None:
    """One person or box on a random beam of the laser, in front of that beam's clean return."""
    beam = int(rng.integers(laser.n_beams))
    kind, side, turn, u = rng.random(), rng.uniform(*spec.box_side_m), rng.uniform(0, math.pi), rng.random()
    person = kind < spec.person_prob
    half = 0.5 * (spec.person_diameter_m if person else side * math.sqrt(2.0))
    far = min(spec.max_dist_m, float(clean[beam]) - half - spec.gap_m)
    if far <= spec.min_dist_m:
        return None
    d = spec.min_dist_m + u * (far - spec.min_dist_m)
    a = pose.theta + laser.angles[beam]
    cx, cy = pose.x + d * math.cos(a), pose.y + d * math.sin(a)
    if person:
        return shapely.Point(cx, cy).buffer(0.5 * spec.person_diameter_m, quad_segs=4)
    h = 0.5 * side
    corners = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    c, s = math.cos(turn), math.sin(turn)
    return Polygon(corners @ np.array([[c, s], [-s, c]]) + (cx, cy))


def occlude(world: VectorMap, pose: Pose, laser: LaserSpec, spec: ClutterSpec,
            rng: np.random.Generator) -> tuple[np.ndarray, list[Polygon]]:
    """Ideal ranges (metres, ``inf`` = no return) from ``pose`` in ``world`` with unmapped objects
    added until ``spec.share`` of the beams are occluded (see the module docstring), and the
    objects. With a share of 0 no object is drawn and no random number is used."""
    clean = world.raycast(pose, laser)
    ranges, objects = clean.copy(), []
    if spec.share == 0.0:
        return ranges, objects
    body = shapely.Point(pose.x, pose.y).buffer(spec.min_dist_m - 0.1)
    walls = shapely.MultiLineString([s.reshape(2, 2) for s in world.segments])
    taken = body
    for _ in range(spec.max_draws):
        obj = _draw_object(spec, pose, laser, clean, rng)
        if obj is None or shapely.distance(obj, walls) < spec.gap_m or shapely.distance(obj, taken) < spec.gap_m:
            continue
        r = np.minimum(ranges, VectorMap(obstacles=(obj,)).raycast(pose, laser))
        share = float(np.mean(r < clean))
        if share > spec.share + spec.tolerance:
            continue
        ranges, taken = r, shapely.union(taken, obj)
        objects.append(obj)
        if share >= spec.share - spec.tolerance:
            break
    return ranges, objects


def occluded_share(clean: np.ndarray, ranges: np.ndarray) -> float:
    """Share of beams whose range ``ranges`` is shorter than the ``clean`` one (metres)."""
    return float(np.mean(np.asarray(ranges) < np.asarray(clean)))
