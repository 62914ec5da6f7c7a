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
from pathlib import Path

import numpy as np
import pytest
from _amcl_cases import LASER, SPREAD, corridor, run_along
from tfloc.baselines._amcl_common import amcl_grid
from tfloc.baselines.amcl import AmclTracker
from tfloc.baselines.amcl.map.map import nav_map
from tfloc.baselines.amcl.map.map_cspace import occ_dist
from tfloc.baselines.amcl.map.map_range import calc_range
from tfloc.baselines.amcl.motion_model.differential_motion_model import differential
from tfloc.baselines.amcl.motion_model.omni_motion_model import omni
from tfloc.baselines.amcl.pf import pf
from tfloc.baselines.amcl.pf import pf_kdtree as kd
from tfloc.baselines.amcl.pf.pf_pdf import drand48, new_stream
from tfloc.baselines.amcl.sensors.laser.beam_model import beam_model
from tfloc.baselines.amcl.sensors.laser.likelihood_field_model import (
    likelihood_field,
    likelihood_table,
)

import tfloc
from tfloc.core.pose import Pose
from tfloc.core.tracker import as_tracker, has_single_scan_mode, is_tracker
from tfloc.errors import ParameterError
from tfloc.maps.grid import GridMap

MAPS = Path(__file__).resolve().parents[2] / "data" / "maps"


@pytest.fixture(scope="module")
def office():
    return tfloc.load_map(MAPS / "office-1.geojson")


@pytest.fixture(scope="module")
def room():
    return tfloc.load_map(MAPS / "test-room.geojson")


def run(vmap, truth: list[Pose], start: Pose, **params) -> tuple[np.ndarray, list, AmclTracker]:
    """An :class:`AmclTracker` along ``truth`` (:func:`_amcl_cases.run_along`)."""
    return run_along(AmclTracker(**params), vmap, truth, start)


def test_registered_as_the_amcl_tracker() -> None:
    tracker = tfloc.get_matcher("amcl")
    assert isinstance(tracker, AmclTracker) and tracker.name == "amcl"
    assert is_tracker(tracker) and not has_single_scan_mode(tracker) and as_tracker(tracker) is tracker
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

@pytest.mark.parametrize(("err", "z"), [(0.05, 0.99), (0.01, 3.0)])
def test_kld_sample_count_is_pf_resample_limit(err, z) -> None:
    """Fox's bound as pf.c writes it: n = ⌈(k − 1)/(2ε) · (1 − 2/(9(k − 1)) + √(2/(9(k − 1))) z)³⌉, clamped."""
    for k in (1, 2, 3, 10, 50, 120, 400, 3000):
        if k <= 1:
            want = 2000
        else:
            x = 1 - 2 / (9 * (k - 1)) + math.sqrt(2 / (9 * (k - 1))) * z
            want = min(max(math.ceil((k - 1) / (2 * err) * x ** 3), 500), 2000)
        assert pf.resample_limit(k, 500, 2000, err, z) == want, k
    assert pf.resample_limit(120, 500, 2000, 0.05, 0.99) == 1343  # pinned: 119/0.1 · 1.0409…³ = 1342.1


def test_resampling_stops_one_past_the_kld_limit() -> None:
    """pf_update_resample stops when the count exceeds the limit of the bins so far: a wide set
    keeps more particles than a narrow one, and the count is limit(k) + 1 (or max_samples)."""
    counts = []
    for sigma in (0.05, 0.5, 3.0):
        rng = new_stream(1)
        s = pf.init_gaussian(rng, np.array([5.0, 5.0, 0.0]), np.diag([sigma ** 2, sigma ** 2, 0.1]), 2000)
        out, *_ = pf.resample(rng, s, 0.0, 0.0, 500, 2000, 0.05, 0.99, np.zeros((0, 2), np.int64),
                              (0.0, 0.0, 0.05, 10, 10))
        assert out.count == min(2000, pf.resample_limit(out.bins, 500, 2000, 0.05, 0.99) + 1)
        assert np.allclose(out.weights, 1.0 / out.count)
        counts.append(out.count)
    assert counts[0] < counts[1] <= counts[2]


def test_heaviest_cluster_of_two_modes() -> None:
    """Two blobs 5 m apart: two clusters; the estimate is the heavier one's mean (Nav2's
    getMaxWeightHyp), not the whole set's."""
    rng = np.random.default_rng(0)
    a = np.column_stack((rng.normal(2.0, 0.1, 1200), rng.normal(2.0, 0.1, 1200), rng.normal(0.3, 0.05, 1200)))
    b = np.column_stack((rng.normal(7.0, 0.1, 800), rng.normal(6.0, 0.1, 800), rng.normal(-2.0, 0.05, 800)))
    poses = np.vstack((a, b))
    for w_b, heavy in ((1.0, a), (2.0, b)):
        w = np.r_[np.ones(1200), np.full(800, w_b)]
        s = pf.clustered(poses, w / w.sum())
        assert s.cluster_weight.size == 2
        k = s.heaviest()
        assert s.cluster_weight[k] == s.cluster_weight.max() and s.cluster_count[k] == len(heavy)
        assert np.allclose(s.cluster_mean[k, :2], heavy[:, :2].mean(axis=0), atol=1e-12)
        assert s.cluster_mean[k, 2] == pytest.approx(math.atan2(np.sin(heavy[:, 2]).sum(), np.cos(heavy[:, 2]).sum()))
        assert np.linalg.norm(s.mean[:2] - s.cluster_mean[k, :2]) > 1.0  # the set's mean lies between
    assert pf.clustered(poses[:1], np.zeros(1)).heaviest() == -1  # no positive weight: no pose


def test_kd_tree_bins_and_the_leaf_table() -> None:
    """Bins of 0.5 m, 0.5 m, 10° (heading not wrapped: θ and θ + 2π are two bins); one leaf per
    occupied bin, found alike by the tree (pf_kdtree_find_node) and the clustering's hash table."""
    rng = np.random.default_rng(1)
    poses = np.column_stack((rng.uniform(-3, 3, 3000), rng.uniform(-3, 3, 3000), rng.uniform(-4, 8, 3000)))
    tree = kd.alloc(3 * len(poses))
    for p in poses:
        kd.insert(tree, p, 1.0)
    keys = np.floor(poses / [0.5, 0.5, math.radians(10.0)]).astype(np.int64)
    assert tree[7][2] == len(np.unique(keys, axis=0))  # leaf_count: KLD's k
    table = kd.leaf_table(tree)
    for key in np.vstack((keys[:500], keys[:500] + [0, 0, 200])):  # present, and absent bins
        assert kd.find(tree, key) == kd.lookup(tree, table, *key)
    assert kd.find(tree, keys[0]) >= 0 and kd.find(tree, keys[0] + [0, 0, 200]) == -1


def moments(model: str, delta: tuple, n: int = 200_000, **alphas) -> tuple[np.ndarray, np.ndarray]:
    """Mean and variance of ``n`` particles moved from the origin (heading 0) by ``delta``."""
    poses = np.zeros((n, 3))
    a = {"alpha1": 0.0, "alpha2": 0.0, "alpha3": 0.0, "alpha4": 0.0, "alpha5": 0.0, **alphas}
    d = np.array(delta, dtype=float)
    if model == "omni":
        omni(new_stream(7), poses, d, d, a["alpha1"], a["alpha2"], a["alpha3"], a["alpha4"], a["alpha5"])
    else:
        differential(new_stream(7), poses, d, d, a["alpha1"], a["alpha2"], a["alpha3"], a["alpha4"])
    return poses.mean(axis=0), poses.var(axis=0)


def test_differential_motion_model_moments() -> None:
    """1 m forward: rot1, rot2 ~ N(0, α2), trans ~ N(1, α3) (Probabilistic Robotics Table 5.6):
    E x = e^(−α2/2), var x = (1 + α3)(1 + e^(−2α2))/2 − e^(−α2), var y = (1 + α3)(1 − e^(−2α2))/2,
    var θ = 2 α2; backward the same, mirrored (Nav2's symmetric noise); a turn in place of 0.5 rad:
    θ ~ N(0.5, α1/4), x ~ N(0, α4/4)."""
    a2, a3 = 0.05, 0.1
    mean, var = moments("differential", (1.0, 0.0, 0.0), alpha2=a2, alpha3=a3)
    want_var = np.array([(1 + a3) * (1 + math.exp(-2 * a2)) / 2 - math.exp(-a2), (1 + a3) * (1 - math.exp(-2 * a2)) / 2,
                         2 * a2])
    assert np.allclose(mean, [math.exp(-a2 / 2), 0.0, 0.0], atol=5 * np.sqrt(want_var / 200_000))
    assert np.allclose(var, want_var, rtol=0.02)
    back, back_var = moments("differential", (-1.0, 0.0, 0.0), alpha2=a2, alpha3=a3)
    assert back[0] == pytest.approx(-math.exp(-a2 / 2), abs=3e-3) and np.allclose(back_var[:2], want_var[:2], rtol=0.02)
    mean, var = moments("differential", (0.0, 0.0, 0.5), alpha1=0.2, alpha4=0.1)
    assert np.allclose(mean, [0.0, 0.0, 0.5], atol=3e-3)
    assert np.allclose(var, [0.1 / 4, 0.0, 0.2 / 4], rtol=0.02, atol=1e-12)


def test_omni_motion_model_moments() -> None:
    """1 m forward: trans ~ N(1, α3), strafe ~ N(0, α5), θ ~ N(0, α2)."""
    mean, var = moments("omni", (1.0, 0.0, 0.0), alpha2=0.04, alpha3=0.1, alpha5=0.2)
    assert np.allclose(mean, [1.0, 0.0, 0.0], atol=3e-3)
    assert np.allclose(var, [0.1, 0.2, 0.04], rtol=0.02)


def test_drand48_is_the_c_librarys() -> None:
    """srand48(0) then drand48(): the first draws of glibc's (and POSIX's) stream."""
    state = new_stream(0)
    x0 = (0 << 16) | 0x330E
    x1 = (0x5DEECE66D * x0 + 0xB) % 2 ** 48
    assert drand48(state) == x1 / 2 ** 48 == pytest.approx(0.170828036106)


# -- the tracker ----------------------------------------------------------------------------------

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
