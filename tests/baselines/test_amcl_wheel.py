"""Tracker ``amcl-wheel``: does the ``amcl`` wheel behave like AMCL before we trust a number from it?

A straight run down the office-1 corridor (scans ray-cast in the map AMCL is given, exact
odometry): from a start 0.4 m and 8.6° off with a spread cloud it converges to the truth, and the
cloud's covariance shrinks over the first scans; which sensor model the wheel runs (the beam model:
its compiled code has no likelihood field); Nav2's update gate (``update_min_d``/``update_min_a``)
decides which scans update the filter; seeded runs repeat exactly. Skipped where the wheel is not
installed."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _amcl_cases import LASER, SPREAD, corridor, run_along
from _paths import MAPS

import tfloc
from tfloc.core.pose import Pose
from tfloc.errors import ParameterError

pytest.importorskip("amcl")
import amcl._amcl_impl  # noqa: E402
from tfloc.baselines._amcl_common import amcl_grid  # noqa: E402
from tfloc.baselines.amcl_wheel import AmclWheelTracker, _pdf_seed_counter  # noqa: E402

OFFICE = MAPS / "office-1.geojson"


@pytest.fixture(scope="module")
def office():
    from tfloc.io.geojson import read_vector_map

    return read_vector_map(OFFICE)


def track(vmap, truth: list[Pose], start: Pose, **params) -> tuple[np.ndarray, list, AmclWheelTracker]:
    """An :class:`AmclWheelTracker` along ``truth`` (:func:`_amcl_cases.run_along`)."""
    return run_along(AmclWheelTracker(**params), vmap, truth, start)


@pytest.mark.parametrize("bad", [{"min_particles": 0}, {"min_particles": 600, "max_particles": 500},
                                 {"max_beams": 1}, {"sigma_hit": 0.0}, {"alpha1": -0.1},
                                 {"laser_model_type": "likelihood_field"}, {"robot_model_type": "ackermann"},
                                 {"recovery_alpha_fast": 1.5}, {"z_hit": 0.0, "z_short": 0.0, "z_max": 0.0,
                                                                "z_rand": 0.0}, {"no_such": 1}])
def test_bad_parameters_are_refused(bad) -> None:
    with pytest.raises(ParameterError, match="amcl"):
        tfloc.get_matcher("amcl-wheel", **bad)


def test_the_wheel_runs_the_beam_model_not_the_likelihood_field() -> None:
    """Nav2's default sensor model is the likelihood field; the wheel compiles only the beam model
    (``BeamModel``, built by ``set_map``; no ``LikelihoodFieldModel``, no distance map)."""
    code = Path(amcl._amcl_impl.__file__).read_bytes()
    assert b"BeamModel" in code and b"map_calc_range" in code
    assert b"LikelihoodField" not in code and b"map_update_cspace" not in code


def test_converges_on_a_straight_corridor_run(office) -> None:
    truth = corridor()
    start = Pose(1.4, 7.3, math.radians(8.6))
    errors, _, _ = track(office, truth, start, **SPREAD)
    assert start.distance_to(truth[0]) > 0.4
    assert np.median(errors[-50:]) < 0.15  # dead reckoning from the start would stay 0.45 m off
    assert errors[-50:].max() < 0.3


def test_covariance_shrinks_from_a_spread_start(office) -> None:
    """North through room N4 (x = 13 m): the spread cloud (σ 0.5 m, 15°) narrows as scans come in."""
    truth = [Pose(13.0, 9.3 + 0.1 * k, math.pi / 2) for k in range(45)]
    errors, ests, _ = track(office, truth, Pose(13.3, 9.0, math.pi / 2 + 0.1), **SPREAD)
    sigma = np.array([e.info["sigma_xy_m"] for e in ests])
    assert sigma[0] > 0.55  # √(0.5² + 0.5²) = 0.71 before the first weighting
    assert sigma[-1] < 0.6 * sigma[0]
    assert np.median(errors[-10:]) < 0.15


def test_the_motion_model_is_the_odometry_model(office) -> None:
    """One 1 m move straight ahead from a point start, the sensor made uninformative (z_rand only):
    the particles' spread is the odometry motion model's (Thrun et al. Sec. 5.4, Nav2's
    ``DifferentialMotionModel``): rot1, rot2 ~ N(0, α2·d²), d ~ N(1, α3·d²), so var θ = 2 α2,
    var x = E[d²] E[cos² rot1] − (E[d] E[cos rot1])², var y = E[d²] E[sin² rot1]."""
    a2, a3 = 0.1, 0.05
    d2 = 1.0 + a3
    expected = np.array([d2 * (1 + math.exp(-2 * a2)) / 2 - math.exp(-a2), d2 * (1 - math.exp(-2 * a2)) / 2, 2 * a2])
    start = Pose(8.0, 7.5, 0.0)
    ranges = office.raycast(start, LASER)
    spreads = []
    for seed in range(3):
        tracker = AmclWheelTracker(alpha1=0.3, alpha2=a2, alpha3=a3, alpha4=0.3, alpha5=0.3, z_hit=0.0, z_short=0.0,
                              z_max=0.0, z_rand=1.0, seed=seed)
        tracker.start(office, LASER, start)
        tracker.step(ranges, Pose(0.0, 0.0, 0.0), 0.0)
        assert tracker.step(ranges, Pose(1.0, 0.0, 0.0), 0.2).info["updated"]
        spreads.append(np.diag(np.array(tracker._filter.get_pose_covariance().to_list())))
    assert np.allclose(np.mean(spreads, axis=0), expected, rtol=0.12)


def test_update_gate_is_navs(office) -> None:
    """0.1 m a scan with update_min_d 0.25 m: the filter updates on the first scan, then every third
    (0.3 m moved); between updates the estimate is the last update's carried by the odometry."""
    truth = corridor(40)
    _, ests, tracker = track(office, truth, truth[0])
    updated = [e.info["updated"] for e in ests]
    assert updated == [k % 3 == 0 for k in range(40)] and tracker.updates == 14
    for k in (1, 2, 4, 5):
        last = 3 * (k // 3)
        carried = ests[last].pose.compose(truth[last].between(truth[k]))
        assert ests[k].pose.distance_to(carried) < 1e-9 and abs(ests[k].pose.theta - carried.theta) < 1e-9
    _, ests, tracker = track(office, truth, truth[0], update_min_d=0.0)
    assert tracker.updates == 40
    # turning in place by 0.08 rad a scan with update_min_a 0.2 rad: every third scan
    turn = [Pose(6.0, 7.5, 0.08 * k) for k in range(10)]
    _, ests, tracker = track(office, turn, turn[0])
    assert [e.info["updated"] for e in ests] == [k % 3 == 0 for k in range(10)]
    # Nav2 gates each odometry axis: 0.2 m diagonally (0.14 m along x and y) does not update
    diagonal = [Pose(2.0 + 0.1414 * k, 7.0 + 0.1414 * k, math.pi / 4) for k in range(2)]
    _, ests, _ = track(office, diagonal, diagonal[0])
    assert [e.info["updated"] for e in ests] == [True, False]


def test_seeded_runs_repeat(office) -> None:
    """The same seed repeats bit for bit (a spread start included, on the wheel build we know)."""
    truth = corridor(40)
    start = Pose(1.2, 7.4, 0.05)
    spread = SPREAD if _pdf_seed_counter() is not None else {}  # another build: a point start only
    runs = [track(office, truth, start, seed=s, **spread)[1] for s in (3, 3, 4)]
    poses = [np.array([e.pose.as_array() for e in run]) for run in runs]
    assert np.array_equal(poses[0], poses[1])
    assert not np.array_equal(poses[0], poses[2])


def test_a_grid_map_is_used_as_given(office) -> None:
    """A vector map runs on its 5 cm rasterisation: the same grid given directly tracks the same."""
    truth = corridor(20)
    _, on_vector, _ = track(office, truth, truth[0])
    grid = amcl_grid(office)
    assert grid.resolution == 0.05
    tracker = AmclWheelTracker()
    tracker.start(grid, LASER, truth[0])
    scans = grid.raycast(np.array([p.as_array() for p in truth]), LASER)
    on_grid = [tracker.step(scans[k], truth[k - 1].between(p) if k else Pose(0.0, 0.0, 0.0), 0.2 * k)
               for k, p in enumerate(truth)]
    assert [e.pose for e in on_grid] == [e.pose for e in on_vector]


def test_start_and_reset_are_carried_by_the_odometry(office) -> None:
    """The start pose is the pose before the first step's odometry; ``reset`` (what a tracking loop
    calls after a failure) starts the filter again at the current scan's pose."""
    truth = corridor(12)
    grid = amcl_grid(office)
    scans = grid.raycast(np.array([p.as_array() for p in truth]), LASER)
    before = Pose(0.8, 7.5, 0.0)  # 0.2 m behind the first scan's pose
    tracker = AmclWheelTracker()
    tracker.start(office, LASER, before)
    first = tracker.step(scans[0], before.between(truth[0]), 0.0)
    assert first.info["updated"] and first.pose.distance_to(truth[0]) < 1e-9
    for k in range(1, 6):
        tracker.step(scans[k], truth[k - 1].between(truth[k]), 0.2 * k)
    wrong = Pose(truth[5].x + 0.3, truth[5].y, 0.0)
    tracker.reset(wrong)
    est = tracker.step(scans[6], truth[5].between(truth[6]), 1.2)
    assert est.info["updated"]
    assert est.pose.distance_to(wrong.compose(truth[5].between(truth[6]))) < 1e-9
