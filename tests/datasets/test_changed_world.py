"""The changed-world generators: the second one (tfloc.datasets.rearranged: doors, moved objects,
carts, people on the crowded office's map) draws worlds as its spec says, seeded, and both write
the bundled changed-* datasets bit for bit (tests/_committed.py)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from _committed import assert_same_file
from _paths import SCEN

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.datasets.changed_world import generate_changed_world
from tfloc.datasets.offices import office_crowded, office_furnished
from tfloc.datasets.rearranged import (
    STYLES,
    RearrangeSpec,
    doorways,
    generate_rearranged,
    movables,
    rearrange,
)
from tfloc.io.scenario import read_scenario
from tfloc.maps.vector import VectorMap

POSES = [Pose(2.0, 7.5, 0.0), Pose(10.0, 3.0, 1.2), Pose(17.0, 12.0, -2.0), Pose(6.5, 10.5, 2.5)]


@pytest.fixture(scope="module")
def office():
    crowded, furnished = office_crowded(), office_furnished()
    items = movables(crowded, furnished)
    keep = {g.wkb for g in items}
    static = VectorMap(walls=crowded.walls, obstacles=tuple(g for g in crowded.obstacles if g.wkb not in keep),
                       outline=crowded.outline)
    return crowded, static, items, doorways(crowded)


def test_doorways_and_movable_objects_of_the_office(office) -> None:
    crowded, static, items, doors = office
    assert len(doors) == 14 and len(items) == 28              # the office's doors; people, chairs, boxes
    for p, q in doors:
        assert abs(np.hypot(*(q - p)) - 0.9) < 1e-9
        assert crowded.is_free(((p + q) / 2)[None, :])[0]     # a doorway is free space
    assert len(static.obstacles) == len(crowded.obstacles) - 28


def test_nothing_changed_is_the_map(office, lms200) -> None:
    crowded, static, items, doors = office
    world, counts = rearrange(crowded, static, items, doors, POSES[0], lms200, RearrangeSpec(),
                              np.random.default_rng(1))
    poses = np.array([p.as_array() for p in POSES])
    np.testing.assert_array_equal(world.raycast(poses, lms200), crowded.raycast(poses, lms200))
    assert not any(counts.values())


@pytest.mark.parametrize("name", list(STYLES))
def test_worlds_are_seeded_and_keep_clear_of_the_laser(office, lms200, name: str) -> None:
    crowded, static, items, doors = office
    spec = STYLES[name][1]
    for k, pose in enumerate(POSES):
        a, ca = rearrange(crowded, static, items, doors, pose, lms200, spec, np.random.default_rng(k))
        b, cb = rearrange(crowded, static, items, doors, pose, lms200, spec, np.random.default_rng(k))
        assert ca == cb and a.segments.tobytes() == b.segments.tobytes()
        known = {g.wkb for g in static.obstacles}
        robot = shapely.Point(pose.x, pose.y)
        for obj in a.obstacles:
            if obj.wkb not in known and obj.wkb not in {g.wkb for g in items}:
                assert obj.distance(robot) >= spec.robot_clearance_m
    if spec.carts:
        counts = [rearrange(crowded, static, items, doors, p, lms200, spec, np.random.default_rng(9))[1]
                  for p in POSES]
        assert sum(c["carts"] for c in counts) > 0 and sum(c["people"] for c in counts) > 0


def test_the_datasets_declare_their_axis() -> None:
    for name, (style, _) in STYLES.items():
        sc = read_scenario(SCEN / name)
        assert sc.extra["axis"] == {"log": "office-crowded-sim", "style": style}
        assert sc.map_path.name == "office-3.geojson"


@pytest.mark.bitwise
def test_second_changed_world_regenerates(office_maps) -> None:
    """The bundled changed-{doors,moved,carts,months} are what generate_rearranged writes (tfloc
    generate): the same bytes, or on another CPU within the last written digit."""
    generate_rearranged(office_maps)
    for name in STYLES:
        for f in ("scans.csv", "scenario.json"):
            assert_same_file(office_maps / "scenarios" / name / f, SCEN / name / f)


@pytest.mark.bitwise
def test_first_changed_world_regenerates(office_maps) -> None:
    """The bundled changed-clutter-{0,10,25} and changed-furniture-gone are what
    generate_changed_world writes."""
    generate_changed_world(office_maps)
    for name in ("changed-clutter-0", "changed-clutter-10", "changed-clutter-25",
                 "changed-furniture-gone"):
        for f in ("scans.csv", "scenario.json"):
            assert_same_file(office_maps / "scenarios" / name / f, SCEN / name / f)


def test_laser_of_the_datasets_is_the_lms200() -> None:
    las = read_scenario(SCEN / "changed-months").laser
    assert las.n_beams == LaserSpec.lms200().n_beams
