"""Tracker ``amcl``: the numba port of Nav2's AMCL, piece by piece against Nav2's formulas.

The likelihood field at known distances (and tfloc's distance field against ``map_cspace``'s
brushfire), the KLD sample count against ``pf_resample_limit``'s formula, the motion models'
sample moments, the heaviest cluster of a two-mode set, seeded repeatability (random injection and
global initialisation included), Nav2's update gate, global initialisation on free cells only, and
bad parameters refused by name. Fidelity against Nav2's own code (the ``amcl`` wheel):
``tests/baselines/test_amcl_fidelity.py``."""

from __future__ import annotations

import heapq
import json
import math

import numpy as np
import pytest
from _amcl_cases import LASER, SPREAD, corridor, run_along
from _paths import MAPS
from tfloc.baselines._amcl_common import amcl_grid
from tfloc.baselines.amcl import AmclTracker
from tfloc.baselines.amcl.map.map import nav_map
from tfloc.baselines.amcl.map.map_cspace import occ_dist
from tfloc.baselines.amcl.map.map_range import calc_range
from tfloc.baselines.amcl.sensors.laser.beam_model import beam_model
from tfloc.baselines.amcl.sensors.laser.likelihood_field_model import (
    likelihood_field,
    likelihood_table,
)

import tfloc
from tfloc.core.pose import Pose
from tfloc.core.tracker import as_tracker, has_single_scan_mode, is_tracker
from tfloc.errors import LibraryMissingError, ParameterError
from tfloc.maps.grid import GridMap


@pytest.fixture(scope="module")
def office():
    return tfloc.load_map(MAPS / "office-1.geojson")


@pytest.fixture(scope="module")
def room():
    return tfloc.load_map(MAPS / "test-room.geojson")


def run(vmap, truth: list[Pose], start: Pose, **params) -> tuple[np.ndarray, list, AmclTracker]:
    """An :class:`AmclTracker` along ``truth`` (:func:`_amcl_cases.run_along`)."""
    return run_along(AmclTracker(**params), vmap, truth, start)


@pytest.mark.parametrize("name", ["amcl", "amcl-wheel"])
def test_registered_as_a_tracker_without_a_single_scan_mode(name: str) -> None:
    try:
        tracker = tfloc.get_matcher(name)
    except LibraryMissingError:
        pytest.skip(f"{name}'s library is not installed")
    assert tracker.name == name and type(tracker).__name__ in ("AmclTracker", "AmclWheelTracker")
    assert is_tracker(tracker) and not has_single_scan_mode(tracker) and as_tracker(tracker) is tracker
    assert has_single_scan_mode(tfloc.get_matcher("tf-plus"))


def test_the_port_has_nav2s_defaults() -> None:
    tracker = tfloc.get_matcher("amcl")
    assert isinstance(tracker, AmclTracker)
    assert tracker.config.laser_model_type == "likelihood_field" and tracker.config.pf_err == 0.05


@pytest.mark.parametrize(("bad", "name"), [
    ({"min_particles": 0}, "min_particles"), ({"min_particles": 600, "max_particles": 500}, "min_particles"),
    ({"max_beams": 1}, "max_beams"), ({"sigma_hit": 0.0}, "sigma_hit"), ({"alpha3": -0.1}, "alpha3"),
    ({"pf_err": 0.0}, "pf_err"), ({"pf_z": -1.0}, "pf_z"), ({"resample_interval": 0}, "resample_interval"),
    ({"laser_likelihood_max_dist": 0.0}, "laser_likelihood_max_dist"),
    ({"laser_model_type": "likelihood_field_prob"}, "laser_model_type"),
    ({"robot_model_type": "ackermann"}, "robot_model_type"), ({"recovery_alpha_fast": 1.5}, "recovery_alpha_fast"),
    ({"global_localization": "yes"}, "global_localization"), ({"seed": -1}, "seed"),
    ({"update_min_d": math.nan}, "update_min_d"), ({"no_such": 1}, "no_such")])
def test_bad_parameters_are_refused_by_name(bad, name) -> None:
    with pytest.raises(ParameterError, match=rf"matcher 'amcl'.*{name}") as err:
        tfloc.get_matcher("amcl", **bad)
    assert err.value.names[0] == name


def test_nav2_plugin_names_and_yaml_style_parameters_are_accepted() -> None:
    t = AmclTracker(robot_model_type="nav2_amcl::OmniMotionModel", laser_model_type="beam", pf_err=0.01,
                    pf_z=3.0, recovery_alpha_slow=0.001, recovery_alpha_fast=0.1, resample_interval=2)
    assert t.config.robot_model_type == "nav2_amcl::OmniMotionModel"


# -- the map and the likelihood field -------------------------------------------------------------

def wall_grid() -> GridMap:
    """21 × 21 cells of 0.1 m from (0, 0), free but for an occupied column at i = 10 (x ∈ [1.0, 1.1))."""
    occ = np.zeros((21, 21), dtype=np.float32)
    occ[:, 10] = 1.0
    return GridMap(occ, 0.1, (0.0, 0.0))


def test_the_distance_field_is_the_distance_to_the_nearest_occupied_cell() -> None:
    grid = wall_grid()
    d = occ_dist(grid, 0.55)
    cols = np.minimum(np.abs(np.arange(21) - 10) * 0.1, 0.55).astype(np.float32)
    assert d.dtype == np.float32 and np.array_equal(d, np.broadcast_to(cols, (21, 21)))
    nav = nav_map(grid)
    assert nav.origin_x == 0.0 + 10 * 0.1 and nav.origin_y == 1.0  # the corner + (size / 2) · scale
    assert (nav.occ_state[:, 10] == 1).all() and (nav.occ_state[:, :10] == -1).all()
    assert nav.free_cells.shape == (20 * 21, 2) and tuple(nav.free_cells[0]) == (0, 0) and tuple(nav.free_cells[1]) == (0, 1)


def test_likelihood_field_weights_at_known_distances() -> None:
    """One particle, four beams: ends in cells 2 and 0 cells from the wall, one off the map, one
    no-return; p = 1 + Σ pz³ with pz = z_hit · exp(−z² / 2σ²) + z_rand / range_max (Nav2's)."""
    grid = wall_grid()
    nav = nav_map(grid)
    z_hit, z_rand, sigma, rmax, cap = 0.6, 0.3, 0.2, 8.0, 0.5
    table, off = likelihood_table(occ_dist(grid, cap), z_hit, z_rand, sigma, rmax, cap)
    pose = np.array([[0.52, 1.03, 0.0]])
    # x = 0.82: Nav2's MAP_GXWX gives floor(8.2 + 0.5) = cell 8 (two from the wall), although the
    # point lies in map_server's cell 8 too; x = 0.96 lies in cell 9 but Nav2 reads cell 10 (the wall)
    ranges = np.array([0.30, 0.44, 5.0, np.inf])
    bearings = np.zeros(4)
    w = np.ones(1)
    total = likelihood_field(pose, w, ranges, bearings, 1, rmax, table, off, *nav.geometry)

    def pz3(z: float) -> float:
        return (z_hit * math.exp(-(z * z) / (2 * sigma * sigma)) + z_rand / rmax) ** 3

    expected = 1.0 + pz3(float(np.float32(0.2))) + pz3(0.0) + pz3(cap)
    assert total == w[0] and w[0] == pytest.approx(expected, rel=1e-14)
    # a weight is multiplied, not replaced; a reading at range_max is ignored
    w = np.array([0.25])
    likelihood_field(pose, w, np.array([rmax, np.nan]), np.zeros(2), 1, rmax, table, off, *nav.geometry)
    assert w[0] == 0.25


def test_beam_model_weights_a_known_range() -> None:
    """A beam toward the wall from 0.55 m before it: map_calc_range's Bresenham range, then the
    hit part only (the reading is long: no short part) plus the random part."""
    grid = wall_grid()
    nav = nav_map(grid)
    pose = np.array([[0.52, 1.03, 0.0]])
    expected_range = calc_range(nav.occ_state, *nav.geometry, 0.52, 1.03, 0.0, 8.0)
    assert expected_range == pytest.approx(0.5)  # cells 5 → 10, Nav2's cell centres
    w = np.ones(1)
    beam_model(pose, w, np.array([0.6]), np.zeros(1), 1, 8.0, nav.occ_state, *nav.geometry,
                      0.5, 0.05, 0.05, 0.5, 0.2, 0.1)
    z = 0.6 - expected_range
    assert w[0] == pytest.approx(1.0 + (0.5 * math.exp(-z * z / 0.08) + 0.5 / 8.0) ** 3, rel=1e-14)


def map_update_cspace(occ: np.ndarray, scale: float, max_dist: float) -> np.ndarray:
    """``map_cspace.cpp``'s brushfire in plain Python: obstacle cells queued by distance, each
    popped cell's neighbours given the distance to the popped cell's source."""
    H, W = occ.shape
    radius = int(max_dist / scale)
    dist = np.full((H, W), max_dist, dtype=np.float32)
    marked = occ == 1
    dist[marked] = 0.0
    queue = [(0.0, n, i, j, i, j) for n, (j, i) in enumerate(np.argwhere(occ == 1))]
    heapq.heapify(queue)
    n = len(queue)
    while queue:
        _, _, i, j, si, sj = heapq.heappop(queue)
        for a, b in ((i - 1, j), (i, j - 1), (i + 1, j), (i, j + 1)):
            if 0 <= a < W and 0 <= b < H and not marked[b, a]:
                d = math.sqrt((a - si) ** 2 + (b - sj) ** 2)
                if d <= radius:
                    dist[b, a] = d * scale
                    marked[b, a] = True
                    n += 1
                    heapq.heappush(queue, (float(dist[b, a]), n, a, b, si, sj))
    return dist


def test_distance_field_against_map_cspaces_brushfire(room, office) -> None:
    """map_cspace propagates each obstacle's distance outwards and misses a nearer obstacle behind
    a corner now and then; tfloc's field is the exact distance: never longer, the same almost
    everywhere (measured: 6.2 % of test-room's cells, 0.11 % of office-1's differ, by ≤ 19 cm)."""
    for vmap, share in ((room, 0.07), (office, 0.002)):
        grid = amcl_grid(vmap)
        ours = occ_dist(grid, 2.0)
        ref = map_update_cspace(nav_map(grid).occ_state, grid.resolution, 2.0)
        assert (ours <= ref).all()
        assert (ours != ref).mean() < share
        assert np.abs(ours - ref).max() < 0.2


# -- the particle filter --------------------------------------------------------------------------

def test_converges_on_a_straight_corridor_run(office) -> None:
    truth = corridor()
    start = Pose(1.4, 7.3, math.radians(8.6))
    errors, ests, _ = run(office, truth, start, **SPREAD)
    assert np.median(errors[-50:]) < 0.1 and errors[-50:].max() < 0.2
    assert ests[-1].info["clusters"] <= 3 and ests[-1].info["particles"] < 1000
    errors, _, _ = run(office, truth, start, z_hit=0.0, **SPREAD)  # an uninformative sensor: no fix
    assert np.median(errors[-50:]) > 0.3


def test_beam_model_converges_too(office) -> None:
    errors, _, _ = run(office, corridor(60), Pose(1.3, 7.35, 0.05), laser_model_type="beam", **SPREAD)
    assert np.median(errors[-20:]) < 0.15


def test_update_gate_is_navs(office) -> None:
    """0.1 m a scan, update_min_d 0.25 m: the first scan and every third (0.3 m) update; between
    updates the estimate is the last one carried exactly by the odometry. Turning in place by
    0.08 rad: every third. 0.2 m diagonally (0.14 m per odometry axis): no update."""
    truth = corridor(40)
    _, ests, tracker = run(office, truth, truth[0])
    assert [e.info["updated"] for e in ests] == [k % 3 == 0 for k in range(40)] and tracker.updates == 14
    for k in (1, 2, 4, 5):
        last = 3 * (k // 3)
        carried = ests[last].pose.compose(truth[last].between(truth[k]))
        assert ests[k].pose.distance_to(carried) < 1e-9 and abs(ests[k].pose.theta - carried.theta) < 1e-9
    assert run(office, truth, truth[0], update_min_d=0.0)[2].updates == 40
    turn = [Pose(6.0, 7.5, 0.08 * k) for k in range(10)]
    assert [e.info["updated"] for e in run(office, turn, turn[0])[1]] == [k % 3 == 0 for k in range(10)]
    diagonal = [Pose(2.0 + 0.1414 * k, 7.0 + 0.1414 * k, math.pi / 4) for k in range(2)]
    assert [e.info["updated"] for e in run(office, diagonal, diagonal[0])[1]] == [True, False]


def test_resample_interval_publishes_only_after_resampling(office) -> None:
    """resample_interval 2: every other update resamples; the pose is published then (and at the
    first scan), otherwise carried by the odometry."""
    truth = corridor(13)
    _, ests, _ = run(office, truth, truth[0], update_min_d=0.0, resample_interval=2)
    assert [e.info["resampled"] for e in ests] == [k % 2 == 1 for k in range(13)]
    for k in (2, 4):
        carried = ests[k - 1].pose.compose(truth[k - 1].between(truth[k]))
        assert ests[k].pose.distance_to(carried) < 1e-9


@pytest.mark.parametrize("params", [SPREAD, {**SPREAD, "laser_model_type": "beam"},
                                    {"recovery_alpha_slow": 0.001, "recovery_alpha_fast": 0.1,
                                     "update_min_d": 0.0, "update_min_a": 0.0},
                                    {"global_localization": True}])
def test_seeded_runs_repeat_bit_for_bit(office, params) -> None:
    truth = corridor(25)
    runs = [run(office, truth, Pose(1.1, 7.45, 0.03), seed=s, **params)[1] for s in (3, 3, 4)]
    poses = [np.array([e.pose.as_array() for e in r]) for r in runs]
    assert np.array_equal(poses[0], poses[1]) and [e.info for e in runs[0]] == [e.info for e in runs[1]]
    assert not np.array_equal(poses[0], poses[2])
    if "recovery_alpha_fast" in params:
        assert sum(e.info["injected"] for e in runs[0]) > 0  # the random poses were drawn


def test_global_initialisation_draws_free_cells_only(office) -> None:
    """``global_localization``: the start pose is ignored and max_particles poses are drawn at the
    Nav2 centres of free cells, uniformly, headings uniform in [−π, π)."""
    tracker = AmclTracker(global_localization=True, seed=5)
    tracker.start(office, LASER, Pose(math.nan, math.nan, math.nan))
    nav = nav_map(amcl_grid(office))
    p = tracker._set.poses
    ox, oy, scale, sx, sy = nav.geometry
    i = np.floor((p[:, 0] - ox) / scale + 0.5).astype(int) + sx // 2
    j = np.floor((p[:, 1] - oy) / scale + 0.5).astype(int) + sy // 2
    assert len(p) == 2000 and (nav.occ_state[j, i] == -1).all()
    assert (p[:, 2] >= -math.pi).all() and (p[:, 2] < math.pi).all() and abs(np.median(p[:, 2])) < 0.2
    rank = np.searchsorted(nav.free_cells[:, 0], i, side="left") / len(nav.free_cells)  # share of free cells left of each
    assert abs(np.mean(rank < 0.5) - 0.5) < 0.05 and len(np.unique(i * sy + j)) > 1900
    assert np.isfinite(tracker.predict(Pose()).x)  # before any scan: the prior's heaviest cluster


def test_global_localization_finds_the_robot_in_the_test_room(room) -> None:
    """A curve through test-room (80 scans, 0.06 m and 0.02 rad a scan) from a uniform start: the
    estimate closes in on the robot in most runs."""
    truth = [Pose(2.0, 2.0, 0.3)]
    for _ in range(79):
        truth.append(truth[-1].compose(Pose(0.06, 0.0, 0.02)))
    final = [run(room, truth, truth[0], global_localization=True, seed=s)[0] for s in range(4)]
    assert all(e[-1] < e[0] for e in final)
    assert sum(e[-1] < 0.25 for e in final) >= 3


def test_a_grid_map_is_used_as_given(office) -> None:
    truth = corridor(20)
    _, on_vector, _ = run(office, truth, truth[0])
    _, on_grid, _ = run(amcl_grid(office), truth, truth[0])
    assert [e.pose for e in on_grid] == [e.pose for e in on_vector]


def test_start_and_reset_are_carried_by_the_odometry(office) -> None:
    truth = corridor(12)
    scans = amcl_grid(office).raycast(np.array([p.as_array() for p in truth]), LASER)
    before = Pose(0.8, 7.5, 0.0)  # 0.2 m behind the first scan's pose
    tracker = AmclTracker()
    tracker.start(office, LASER, before)
    assert tracker.predict(before.between(truth[0])).distance_to(truth[0]) < 1e-12
    first = tracker.step(scans[0], before.between(truth[0]), 0.0)
    assert first.info["updated"] and first.pose.distance_to(truth[0]) < 1e-9  # a point start: every particle there
    for k in range(1, 6):
        tracker.step(scans[k], truth[k - 1].between(truth[k]), 0.1 * k)
    wrong = Pose(truth[5].x + 0.3, truth[5].y, 0.0)
    tracker.reset(wrong)
    est = tracker.step(scans[6], truth[5].between(truth[6]), 0.6)
    assert est.info["updated"] and est.pose.distance_to(wrong.compose(truth[5].between(truth[6]))) < 1e-9


def test_info_is_small_and_serialisable(office) -> None:
    _, ests, _ = run(office, corridor(4), Pose(1.05, 7.5, 0.0), **SPREAD)
    info = ests[0].info
    assert {"updated", "resampled", "particles", "clusters", "cov_trace", "cluster_cov_trace",
            "sigma_xy_m", "sigma_theta_rad", "injected"} <= set(info)
    assert len(json.dumps(info)) < 400 and info["particles"] >= 500 and info["cov_trace"] > 0


def test_warm_compiles_without_touching_the_tracker(office) -> None:
    tracker = AmclTracker()
    ranges = office.raycast(Pose(3.0, 7.5, 0.0), LASER)
    tracker.warm(office, LASER, ranges, Pose(3.0, 7.5, 0.0))
    with pytest.raises(RuntimeError, match="before start"):
        tracker.step(ranges, Pose(), 0.0)
