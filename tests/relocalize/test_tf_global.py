"""tf-global: the place signature's invariances, the index's disk cache, global answers, local
problems and bad parameters."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import shapely
from _paths import MAPS

import tfloc
from tfloc.core.matcher import check_solvable, get_matcher, solves_global
from tfloc.core.pose import Pose, angdiff
from tfloc.errors import InvalidProblemError, ParameterError
from tfloc.maps.vector import VectorMap
from tfloc.relocalize.index import IndexConfig, index_key, load_or_build, map_digest, place_index
from tfloc.relocalize.matcher import TurningFunctionGlobalMatcher, distinct
from tfloc.relocalize.signature import SignatureConfig, scan_signature

#: a full-circle scanner: turning it by k beams rolls its ranges by k (an exact rotation)
RING = tfloc.LaserSpec.from_degrees(10.0, 359.0, 1.0, -180.0)
SIG = SignatureConfig(edge_weight=1.0)  # every block on, the edge spectrum included


def _sig(room, pose, laser=RING, cfg=SIG) -> np.ndarray:
    return scan_signature(room.raycast(pose, laser), laser, cfg)


def test_signature_is_the_same_when_the_robot_turns(test_room) -> None:
    here = Pose(3.0, 3.5, 0.0)
    base = _sig(test_room, here)
    elsewhere = np.linalg.norm(_sig(test_room, Pose(8.8, 1.5, 0.0)) - base)
    for k in (17, 90, 200):
        ranges = np.roll(test_room.raycast(here, RING), k)          # the robot turned by k°
        turned = scan_signature(ranges, RING, SIG)
        assert np.linalg.norm(turned - base) < 0.25 * elsewhere, k
    # the same through the map's own ray cast at another heading (beams not exactly rolled)
    turned = _sig(test_room, Pose(3.0, 3.5, 1.234))
    assert np.linalg.norm(turned - base) < 0.25 * elsewhere


def test_signature_of_a_nearby_position_is_near(test_room) -> None:
    base = _sig(test_room, Pose(3.0, 3.5, 0.0))
    near = np.linalg.norm(_sig(test_room, Pose(3.2, 3.4, 0.0)) - base)
    far = [np.linalg.norm(_sig(test_room, Pose(x, y, 0.0)) - base)
           for x, y in ((8.8, 1.5), (1.0, 7.0), (6.0, 0.6))]
    assert near < min(far)


def test_signature_of_a_degenerate_scan_is_finite(lms200) -> None:
    ranges = np.full(lms200.n_beams, np.inf)
    ranges[90] = 2.0
    s = scan_signature(ranges, lms200, SignatureConfig())
    assert s.shape == (SignatureConfig().size,) and np.isfinite(s).all()


SMALL = IndexConfig(step=0.5, headings=8)


def test_index_is_built_once_then_read_from_disk(test_room, lms200, tmp_path) -> None:
    first = load_or_build(test_room, lms200, SMALL, tmp_path)
    assert not first.loaded and first.build_cpu_s > 0
    files = list(tmp_path.glob("*.npz"))
    assert [f.stem for f in files] == [first.key]
    same = tfloc.load_map(_room_path())                 # the same file, a new map object
    second = load_or_build(same, lms200, SMALL, tmp_path)
    assert second.loaded and second.key == first.key
    np.testing.assert_array_equal(second.poses, first.poses)
    np.testing.assert_array_equal(second.signatures, first.signatures)
    assert second.build_cpu_s == pytest.approx(first.build_cpu_s)


def test_a_changed_map_laser_or_parameter_builds_a_new_index(test_room, lms200, tmp_path) -> None:
    base = load_or_build(test_room, lms200, SMALL, tmp_path)
    moved = VectorMap(walls=(*test_room.walls, shapely.LineString([(4.0, 6.0), (5.0, 6.0)])),
                      obstacles=test_room.obstacles, outline=test_room.outline)
    assert map_digest(moved) != map_digest(test_room)
    other = load_or_build(moved, lms200, SMALL, tmp_path)
    assert not other.loaded and other.key != base.key
    assert index_key(test_room, RING, SMALL) != base.key
    assert index_key(test_room, lms200, IndexConfig(step=0.4, headings=8)) != base.key
    assert len(list(tmp_path.glob("*.npz"))) == 2


def test_a_damaged_cache_file_is_rebuilt(test_room, lms200, tmp_path) -> None:
    base = load_or_build(test_room, lms200, SMALL, tmp_path)
    (tmp_path / f"{base.key}.npz").write_bytes(b"not an index")
    again = load_or_build(test_room, lms200, SMALL, tmp_path)
    assert not again.loaded and len(again.poses) == len(base.poses)


def test_the_index_is_kept_in_memory_per_map(test_room, lms200, tmp_path) -> None:
    a = place_index(test_room, lms200, SMALL, str(tmp_path))
    assert place_index(test_room, lms200, SMALL, str(tmp_path)) is a


def _room_path() -> Path:
    return MAPS / "test-room.geojson"


@pytest.fixture(scope="module")
def matcher(tmp_path_factory) -> TurningFunctionGlobalMatcher:
    return get_matcher("tf-global", cache_dir=str(tmp_path_factory.mktemp("index")))


@pytest.mark.parametrize("true", [Pose(3.0, 3.5, 0.3), Pose(8.6, 2.0, 2.5), Pose(1.2, 6.5, -1.2)])
def test_a_scan_is_found_without_a_guess(matcher, test_room, lms200, true) -> None:
    rng = np.random.default_rng(7)
    ranges = test_room.raycast(true, lms200) + rng.normal(0, 0.01, lms200.n_beams)
    problem = tfloc.Problem(test_room, lms200, ranges, None)
    assert problem.is_global and solves_global(matcher)
    check_solvable(matcher, problem)
    matcher.prepare(problem)
    est = matcher.localize(problem)
    assert est.pose.distance_to(true) <= 0.10
    assert abs(angdiff(est.pose.theta, true.theta)) <= math.radians(2.0)
    assert est.hypotheses[0] == est.pose and 1 <= len(est.hypotheses) <= 5
    assert est.info["mode"] == "global"
    assert matcher.score(problem, est.pose) <= matcher.score(problem, Pose(true.x + 0.5, true.y, true.theta))


def test_a_local_problem_is_answered_from_its_guess(matcher, test_room, lms200) -> None:
    true = Pose(3.0, 3.5, 0.3)
    problem = tfloc.Problem(test_room, lms200, test_room.raycast(true, lms200), Pose(3.6, 3.1, 0.4))
    est = matcher.localize(problem)
    assert est.info["mode"] == "local" and est.hypotheses == (est.pose,)
    assert est.pose.distance_to(true) <= 0.10


def test_a_local_matcher_refuses_a_global_problem(test_room, lms200) -> None:
    problem = tfloc.Problem(test_room, lms200, test_room.raycast(Pose(3, 3.5, 0), lms200), None)
    with pytest.raises(InvalidProblemError, match="global problem"):
        check_solvable(get_matcher("tf-plus"), problem)


def test_hypotheses_are_distinct() -> None:
    poses = np.array([[0, 0, 0], [0.1, 0, 0], [0.1, 0, 1.0], [2, 0, 0], [0, 0, 0.05]], dtype=float)
    assert distinct(poses, 5, 0.3, math.radians(10)) == [0, 2, 3]
    assert distinct(poses, 2, 0.3, math.radians(10)) == [0, 2]


@pytest.mark.parametrize("params, message", [
    ({"places": 0}, r"places must be >= 1"),
    ({"local": "maybe"}, r"local must be one of 'tf-plus', 'global'"),
    ({"index": {"step": 0.0}}, r"index.step must be > 0"),
    ({"index": {"signature": {"range_cap": -1.0}}}, r"index.signature.range_cap must be > 0"),
    ({"resolver": {"search_radius": math.nan}}, r"resolver.search_radius must be a finite number"),
    ({"placess": 3}, r"unknown parameter\(s\) placess"),
    ({"no_return": "maybe"}, r"no_return must be one of 'unknown', 'far'"),
    ({"profile_truncation": 0.0}, r"profile_truncation must be > 0"),
    ({"index": {"profile": {"sectors": 0}}}, r"index.profile.sectors must be >= 1"),
])
def test_bad_parameters_are_refused(params, message) -> None:
    with pytest.raises(ParameterError, match=rf"matcher 'tf-global': {message}"):
        get_matcher("tf-global", **params)


def test_a_kidnapped_tracker_notices_by_its_score_and_relocalizes(matcher, test_room, lms200) -> None:
    from tfloc.relocalize.recovery import RecoveringTracker

    tracker = RecoveringTracker(get_matcher("tf-plus"), matcher)
    path = [Pose(2.0, 3.0 + 0.2 * k, 1.2) for k in range(4)]           # walking up the room
    path += [Pose(8.6, 2.0 + 0.2 * k, 2.5) for k in range(5)]          # carried off, turned
    step = Pose(0.2 * math.cos(0.37), 0.2 * math.sin(0.37), 0.0)      # what the wheels say
    tracker.prepare(tfloc.Problem(test_room, lms200, test_room.raycast(path[0], lms200), path[0]))
    tracker.start(test_room, lms200, path[0])
    rng = np.random.default_rng(3)
    right, relocs = [], []
    for k, true in enumerate(path[1:], 1):
        ranges = test_room.raycast(true, lms200) + rng.normal(0, 0.01, lms200.n_beams)
        est = tracker.step(ranges, step if k < 4 else Pose(0.2, 0.0, 0.0), float(k))
        right.append(est.pose.distance_to(true) <= 0.10
                     and abs(angdiff(est.pose.theta, true.theta)) <= math.radians(2.0))
        relocs.append(est.info["relocalized"])
    assert right[:3] == [True] * 3 and not any(relocs[:3])       # tracking: no false jump
    assert not right[3]                                          # the kidnap: lost ...
    assert any(right[4:6]) and right[-1] and any(relocs[4:])     # ... found within two scans


def test_recovery_parameters_are_checked() -> None:
    from tfloc.relocalize.recovery import RecoveringTracker

    with pytest.raises(ParameterError, match="lost_after must be >= 1"):
        RecoveringTracker(None, None, lost_after=0)


def test_a_map_without_free_lattice_positions_gets_no_answer(test_room, lms200, tmp_path) -> None:
    m = get_matcher("tf-global", cache_dir=str(tmp_path), index={"clearance": 20.0})
    problem = tfloc.Problem(test_room, lms200, test_room.raycast(Pose(3, 3.5, 0), lms200), None)
    m.prepare(problem)
    est = m.localize(problem)
    assert est.info["status"] == "no-answer" and not est.converged


def test_a_local_problem_can_be_searched_globally(test_room, lms200, tmp_path) -> None:
    m = get_matcher("tf-global", cache_dir=str(tmp_path), local="global")
    true = Pose(3.0, 3.5, 0.3)
    far_guess = Pose(8.5, 1.0, -2.0)                         # a wrong guess is ignored
    est = m.localize(tfloc.Problem(test_room, lms200, test_room.raycast(true, lms200), far_guess))
    assert est.info["mode"] == "global" and est.pose.distance_to(true) <= 0.10


def test_tfloc_index_builds_then_loads_the_index_of_a_dataset(test_room, lms200, tmp_path, capsys) -> None:
    from tfloc.cli import main
    from tfloc.io.scenario import Scan, write_scenario

    ranges = test_room.raycast(Pose(3.0, 3.5, 0.3), lms200)
    data = write_scenario(tmp_path / "room-global", "room-global", _room_path(), lms200,
                          [Scan("g0", "global", ranges, None, None)], mode="global")
    args = ["index", "--dataset", str(data), "--param", f"cache_dir='{tmp_path / 'idx'}'",
            "--param", "index.headings=4"]
    assert main(args) == 0
    assert "built" in capsys.readouterr().out
    assert len(list((tmp_path / "idx").glob("*.npz"))) == 1
    assert main(args) == 0
    assert "loaded" in capsys.readouterr().out
    assert main([*args, "--param", "index.step=-1"]) == 2
    assert "--param index.step: matcher 'tf-global': index.step must be > 0" in capsys.readouterr().err


def test_tf_global_resolves_place_by_place_too(test_room, lms200, tmp_path) -> None:
    m = get_matcher("tf-global", cache_dir=str(tmp_path), resolve="per-place", places=6)
    true = Pose(8.6, 2.0, 2.5)
    est = m.localize(tfloc.Problem(test_room, lms200, test_room.raycast(true, lms200), None))
    assert est.pose.distance_to(true) <= 0.10 and abs(angdiff(est.pose.theta, true.theta)) <= 0.035


def test_an_unwritable_cache_still_gives_the_index(test_room, lms200, tmp_path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    idx = load_or_build(test_room, lms200, SMALL, blocker / "index")
    assert not idx.loaded and len(idx.poses) > 0


def test_a_grid_map_is_keyed_by_its_cells() -> None:
    from tfloc.maps.grid import GridMap

    occ = np.zeros((40, 60), dtype=np.float32)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = 1.0
    a = GridMap(occ, 0.1, (0.0, 0.0))
    moved = occ.copy()
    moved[20, 30] = 1.0
    assert map_digest(GridMap(occ.copy(), 0.1, (0.0, 0.0))) == map_digest(a)
    assert map_digest(GridMap(moved, 0.1, (0.0, 0.0))) != map_digest(a)
    assert map_digest(GridMap(occ, 0.1, (0.5, 0.0))) != map_digest(a)
    assert map_digest(GridMap(occ, 0.05, (0.0, 0.0))) != map_digest(a)


def test_a_range_profile_is_the_sector_median_and_a_real_no_return_is_unknown(lms200) -> None:
    from tfloc.relocalize.profile import ProfileConfig, index_profiles, query_profiles

    cfg = ProfileConfig(sectors=6, margin=0.0, cap=10.0)
    ranges = np.full(lms200.n_beams, 4.0)
    ranges[10:13] = 0.5                                   # a chair leg in three beams
    ranges[-40:] = np.inf                                 # the last sector (30 beams) and more return nothing
    real = query_profiles(ranges, lms200, cfg, np.zeros(1))[0]
    assert real[0] == pytest.approx(0.4) and np.isnan(real[-1])   # the median ignores the leg
    virtual = index_profiles(ranges[None, :], lms200, cfg)[0]
    assert virtual[-1] == 1.0 and virtual[0] == pytest.approx(0.4)  # the map's no-return is open space
    far = query_profiles(ranges, lms200, cfg, np.zeros(1), no_return="far")[0]
    assert far[-1] == 1.0


def test_the_profile_distance_is_a_truncated_mean_over_known_sectors_at_the_best_shift() -> None:
    from tfloc.relocalize.profile_kernel import place_distances

    rng = np.random.default_rng(5)
    profiles = rng.random((8, 50)).astype(np.float32)      # sector-major: 8 sectors x 50 entries
    queries = rng.random((3, 8)).astype(np.float32)
    queries[1, [2, 5]] = np.nan
    base = rng.random(50)
    got = place_distances(base, profiles, queries, 0.3, 2.0)
    diff = np.minimum(np.abs(queries[:, :, None] - profiles[None]), np.float32(0.3))
    rho = np.nanmean(np.where(np.isnan(queries)[:, :, None], np.nan, diff), axis=1).min(axis=0)
    np.testing.assert_allclose(got, base + 2.0 * rho, rtol=1e-6)


def test_the_profile_ranks_the_true_place_first(test_room, lms200, tmp_path) -> None:
    cfg = IndexConfig(step=0.5, headings=8)
    idx = load_or_build(test_room, lms200, cfg, tmp_path)
    assert idx.profiles.shape == (cfg.profile.sectors, len(idx.poses))
    again = load_or_build(test_room, lms200, cfg, tmp_path)
    np.testing.assert_array_equal(again.profiles, idx.profiles)
    from tfloc.relocalize.profile import query_profiles, query_shifts

    entry = 37
    ranges = test_room.raycast(Pose.from_array(idx.poses[entry]), lms200)
    prof = query_profiles(ranges, lms200, cfg.profile, query_shifts(cfg.headings, 5))
    d = idx.distances(np.zeros(idx.signatures.shape[1]), prof, 1.0, 0.1) - np.sqrt(idx.norms)
    assert int(np.argmin(d)) == entry
