"""tf-plus in a changed world: the free-space cap of the coarse search, the short and bounded
see-through terms of the selection, object-sized groups, the refinement without unmapped returns,
and the named configuration (tfloc.tfplus.config.CHANGED_WORLD)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from _paths import ROOT
from _tf_cases import TRUE, cost_cases, noisy_scan
from shapely.geometry import Point, box

from tfloc import Pose, VectorMap
from tfloc.core.laser import LaserSpec
from tfloc.core.presets import resolve
from tfloc.harness.config import load_config
from tfloc.harness.workspace import problem_of
from tfloc.io.scenario import load_dataset
from tfloc.maps.build import rasterize
from tfloc.tfplus.config import CHANGED_WORLD, TfPlusConfig, coarse_view
from tfloc.tfplus.cost import (
    bound_see_through,
    object_groups,
    scan_cost,
    scan_cost_steps,
    see_through,
    short_beams,
    unmapped,
)
from tfloc.tfplus.cost_kernel import beam_flags_kernel, see_through_kernel
from tfloc.tfplus.matcher import TurningFunctionPlusMatcher
from tfloc.tfplus.view import map_view

ROOM = VectorMap(outline=box(0, 0, 8, 6), name="room")
LASER = LaserSpec.lms200()


def _with_person(pose: Pose, at: tuple[float, float]) -> np.ndarray:
    """The room's scan from ``pose`` with a person (0.3 m disc) standing at ``at``."""
    world = VectorMap(outline=box(0, 0, 8, 6), obstacles=(Point(*at).buffer(0.15, quad_segs=4),))
    return world.raycast(pose, LASER)


def test_the_default_configuration_has_every_changed_world_term_off() -> None:
    cfg = TfPlusConfig()
    assert cfg.free_distance is None and cfg.short_residual is None and not cfg.short_refine
    assert cfg.see_through_share == 1.0 and cfg.object_extent is None
    changed = TurningFunctionPlusMatcher(**CHANGED_WORLD).config
    assert all(getattr(changed, k) == v for k, v in CHANGED_WORLD.items())


@pytest.mark.parametrize("run", ["robustness.toml", "robustness-full.toml", "dev/changed-world.toml",
                                 "dev/changed-world-heldout.toml", "dev/changed-world-guard.toml"])
def test_run_configurations_name_the_configuration_as_it_is(run: str) -> None:
    spec = next(m for m in load_config(ROOT / "benchmarks" / run).matchers if m.label == "tf-plus-changed")
    assert spec.name == "tf-plus-changed" and not spec.params  # the preset, by its name
    assert resolve(spec.name, {}) == ("tf-plus", CHANGED_WORLD)


def test_free_space_caps_the_coarse_field_there_only() -> None:
    cfg = dataclasses.replace(TfPlusConfig(), free_distance=0.05)
    plain, capped = coarse_view(ROOM, TfPlusConfig()), coarse_view(ROOM, cfg)
    assert capped.table.dtype == plain.table.dtype
    assert (capped.table <= plain.table).all() and capped.table.max() == plain.table.max()
    inside = capped.field(np.array([[4.0, 3.0]]))[0]            # the room's middle: free
    outside = capped.field(np.array([[-0.5, 3.0]]))[0]          # beyond the wall: not free
    assert inside == pytest.approx(0.05) and outside == pytest.approx(plain.field(np.array([[-0.5, 3.0]]))[0])


def test_a_person_is_short_a_wall_seen_from_a_wrong_pose_is_not() -> None:
    pose = Pose(2.0, 3.0, 0.0)
    ranges = _with_person(pose, (4.0, 3.0))
    short = short_beams(ROOM, LASER, ranges, pose.as_array()[None, :], 0.3)[0]
    hit = np.isfinite(ranges) & (np.abs(ranges - ROOM.raycast(pose, LASER)) > 0.3)
    assert hit.any() and (short == hit).all()
    off = Pose(2.1, 3.0, 0.0).as_array()[None, :]               # 10 cm off: nothing 30 cm short
    assert not short_beams(ROOM, LASER, ROOM.raycast(pose, LASER), off, 0.3).any()


def test_object_groups_are_object_sized() -> None:
    pose = Pose(2.0, 3.0, 0.0)
    ranges = _with_person(pose, (4.0, 3.0))
    groups = object_groups(LASER, ranges, 1.0)
    person = np.isfinite(ranges) & (ranges < 2.2)
    assert (groups[person] >= 0).all() and len(set(groups[person])) == 1
    assert (groups[~person] < 0).sum() > 150                    # the walls: longer than 1 m
    every = object_groups(LASER, ranges, None)
    assert (every == np.where(np.isfinite(ranges), np.arange(LASER.n_beams), -1)).all()
    short = np.zeros((1, LASER.n_beams), dtype=bool)
    short[0, np.flatnonzero(person)[:-1]] = True                # all but one of the person's
    assert not unmapped(short, groups).any()
    short[0, person] = True
    assert (unmapped(short, groups)[0] == person).all()


def test_bounded_see_through_adds_at_most_its_share() -> None:
    c, n = 0.1, 100
    pen = np.zeros((3, n))
    see = np.zeros((3, n), dtype=bool)
    see[0, :3], see[1, :40], see[2, :] = True, True, True
    full = pen.copy()
    bound_see_through(full, see, c, 1.0)
    assert (full == np.where(see, c * c, 0.0)).all()
    bound_see_through(pen, see, c, 0.05)
    assert pen[0].sum() == pytest.approx(3 * c * c)             # below the share: in full
    assert pen[1].sum() == pytest.approx(5 * c * c) and pen[2].sum() == pytest.approx(5 * c * c)


def test_the_combined_march_sees_through_as_the_see_through_march() -> None:
    grid = rasterize(ROOM, 0.05)
    rng = np.random.default_rng(3)
    poses = np.column_stack((rng.uniform(0.5, 7.5, 6), rng.uniform(0.5, 5.5, 6), rng.uniform(-3, 3, 6)))
    ranges = noisy_scan(ROOM, LASER, Pose(*poses[0]), 1)
    ranges[::9] = np.inf
    ranges[4::13] += 0.7
    ranges[7::11] -= 0.9
    args = (grid.occupied, float(grid.origin[0]), float(grid.origin[1]), float(grid.resolution), poses,
            np.asarray(LASER.angles, dtype=float), ranges, float(LASER.max_range))
    for margin in (0.0, 0.1):
        see, short = beam_flags_kernel(grid.occupied, grid.free, *args[1:], margin, 0.3, True,
                                       np.ones(LASER.n_beams, dtype=bool))
        assert (see == see_through_kernel(*args, margin)).all()
        alone = beam_flags_kernel(grid.occupied, grid.free, *args[1:], margin, 0.3, False,
                                  np.ones(LASER.n_beams, dtype=bool))
        assert not alone[0].any() and (alone[1] == short).all()
    assert short.any()


@pytest.mark.parametrize("grid", [False, True])
def test_compiled_changed_world_cost_equals_the_numpy_steps(grid: bool, test_room, lms200) -> None:
    rng = np.random.default_rng(11)
    for seed, (m, field, ranges) in enumerate(cost_cases(test_room, lms200, grid)):
        ranges[60:66] -= 1.0                      # an object in front of a wall
        poses = np.vstack((TRUE.as_array(), TRUE.as_array() + rng.normal(0, [0.3, 0.3, 0.05], (3, 3))))
        for extent in (None, 1.0):
            args = (m, lms200, ranges, poses, 6, 0.1, True, field, 0.05, 0.05, 0.3, extent)
            got, ref = scan_cost(*args), scan_cost_steps(*args)
            assert got.tobytes() == ref.tobytes(), (seed, extent)
        plain = scan_cost(m, lms200, ranges, poses, 6, 0.1, True, field)
        assert (scan_cost(m, lms200, ranges, poses, 6, 0.1, True, field, None, 1.0) == plain).all()
        assert (got <= plain).all()               # the short and bounded terms only lower it


def test_unmapped_objects_cost_less_at_the_true_pose() -> None:
    pose = Pose(2.0, 3.0, 0.0)
    ranges = _with_person(pose, (4.0, 3.0))
    field = map_view(ROOM, 0.05, 0.3, 0.3)
    at = pose.as_array()[None, :]
    plain = scan_cost(ROOM, LASER, ranges, at, 6, 0.1, True, field)[0]
    short = scan_cost(ROOM, LASER, ranges, at, 6, 0.1, True, field, 0.05, 1.0, 0.3, 1.0)[0]
    assert short == pytest.approx(plain / 4, rel=0.05)          # the person's beams: 5 cm, not 10
    assert see_through(ROOM, LASER, ranges, at, 0.1).sum() == 0


def test_the_changed_world_configuration_finds_what_tf_plus_misses() -> None:
    """Development scans of the 25 % clutter world on which tf-plus picks a pose 1-3 m off and
    its changed-world configuration the true one (benchmarks/dev/changed-world.toml)."""
    scenario, scans = load_dataset(str(ROOT / "data" / "scenarios" / "changed-clutter-25"))
    default, changed = TurningFunctionPlusMatcher(), TurningFunctionPlusMatcher(**CHANGED_WORLD)
    for sid in ("d1-a1-024", "d2-a3-022", "d3-a2-018"):
        p = problem_of(scenario, scans[sid])
        for m in (default, changed):
            m.prepare(p)
        truth = scans[sid].true
        a, b = default.localize(p).pose, changed.localize(p).pose
        assert a.distance_to(truth) > 0.5
        assert b.distance_to(truth) < 0.1 and abs(math.remainder(b.theta - truth.theta, math.tau)) < 0.035
