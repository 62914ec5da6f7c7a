"""The odometry motion model against Probabilistic Robotics Table 5.6 (moments of many draws)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _paths import SCEN

from tfloc.core.pose import Pose
from tfloc.datasets.motion import (
    OdometryNoise,
    Slip,
    decompose,
    draw_odometry,
    recompose,
    sample_increments,
    sample_parts,
)
from tfloc.errors import ConfigError


@pytest.mark.parametrize("alphas", [(0.05, 0.02, 0.1, 0.03), (0.2, 0.2, 0.2, 0.2), (0.0, 0.1, 0.0, 0.1)])
def test_sampled_parts_have_the_books_means_and_variances(alphas):
    delta = Pose(0.8, 0.3, 0.5)
    rot1, trans, rot2 = decompose(delta)
    a1, a2, a3, a4 = alphas
    want_var = np.array([a1 * rot1 ** 2 + a2 * trans ** 2,
                         a3 * trans ** 2 + a4 * (rot1 ** 2 + rot2 ** 2),
                         a1 * rot2 ** 2 + a2 * trans ** 2])
    n = 200_000
    p = sample_parts(delta, OdometryNoise(*alphas), np.random.default_rng(1), n)
    assert np.all(np.abs(p.mean(axis=0) - [rot1, trans, rot2]) <= 4 * np.sqrt(want_var / n) + 1e-12)
    # sample variance of n normals: relative standard error sqrt(2/n) ≈ 0.3 %; allow 2 %
    np.testing.assert_allclose(p.var(axis=0), want_var, rtol=0.02, atol=1e-12)


def test_increments_are_the_parts_recomposed():
    delta, noise = Pose(0.5, -0.2, 0.3), OdometryNoise(0.1, 0.1, 0.1, 0.1)
    p = sample_parts(delta, noise, np.random.default_rng(4), 50)
    inc = sample_increments(delta, noise, np.random.default_rng(4), 50)
    np.testing.assert_allclose(inc, recompose(p[:, 0], p[:, 1], p[:, 2]))
    np.testing.assert_allclose(recompose(*decompose(delta))[0], delta.as_array(), atol=1e-12)


def test_decompose_turn_in_place_has_no_first_rotation():
    assert decompose(Pose(0.0, 0.0, 0.7)) == (0.0, 0.0, pytest.approx(0.7))
    r1, t, r2 = decompose(Pose(0.0, 1.0, 0.0))
    assert (r1, t, r2) == (pytest.approx(math.pi / 2), pytest.approx(1.0), pytest.approx(-math.pi / 2))


def test_zero_noise_odometry_is_the_true_motion_in_its_own_frame():
    rng = np.random.default_rng(0)
    true = np.column_stack([np.cumsum(rng.uniform(0, 0.2, 50)), np.cumsum(rng.uniform(-0.1, 0.1, 50)),
                            np.cumsum(rng.uniform(-0.2, 0.2, 50))])
    odom, slipped = draw_odometry(true, OdometryNoise(0, 0, 0, 0), rng)
    assert not slipped.any()
    start = Pose.from_array(true[0])
    for k in (10, 49):
        got = start.compose(Pose.from_array(odom[0]).between(Pose.from_array(odom[k])))
        np.testing.assert_allclose(got.as_array(), true[k], atol=1e-9)


def test_slip_jumps_are_unobserved_and_of_the_given_size():
    true = np.column_stack([np.arange(400) * 0.1, np.zeros(400), np.zeros(400)])
    odom, slipped = draw_odometry(true, OdometryNoise(0, 0, 0, 0), np.random.default_rng(3),
                                  Slip(prob=0.05, min_m=0.3, max_m=1.0))
    assert 5 <= slipped.sum() <= 40
    steps = np.hypot(*np.diff(odom[:, :2], axis=0).T)
    jump = np.hypot(*(np.diff(odom[:, :2], axis=0) - np.diff(true[:, :2], axis=0)).T)
    assert np.all(jump[~slipped[1:]] < 1e-9)
    assert np.all((jump[slipped[1:]] >= 0.3 - 1e-9) & (jump[slipped[1:]] <= 1.0 + 1e-9))
    assert steps.size == 399


def test_reproducible_and_checked():
    true = np.column_stack([np.arange(30) * 0.1, np.zeros(30), np.zeros(30)])
    a = draw_odometry(true, OdometryNoise(), np.random.default_rng(7), Slip())[0]
    b = draw_odometry(true, OdometryNoise(), np.random.default_rng(7), Slip())[0]
    assert np.array_equal(a, b)
    with pytest.raises(ConfigError):
        OdometryNoise(-0.1, 0, 0, 0)
    with pytest.raises(ConfigError):
        Slip(prob=1.5)


def test_densify_keeps_the_poses_and_bounds_the_steps():
    from tfloc.datasets.motion import densify

    P = np.array([[0, 0, 0], [1.0, 0, 0], [1.0, 0, 1.2], [1.0, 0.05, 1.25], [3.0, 2.0, -3.0]])
    dense, at = densify(P, 0.1, math.radians(3))
    np.testing.assert_allclose(dense[at], np.column_stack([P[:, :2], np.angle(np.exp(1j * P[:, 2]))]))
    steps = np.hypot(*np.diff(dense[:, :2], axis=0).T)
    turns = np.abs(np.angle(np.exp(1j * np.diff(dense[:, 2]))))
    assert steps.max() <= 0.1 + 1e-9 and turns.max() <= math.radians(3) + 1e-9
    assert at[1] == 10 and at[2] - at[1] == math.ceil(1.2 / math.radians(3))
    # every step is a turn in place or a straight drive (forwards or backwards)
    for a, b in zip(dense[:-1], dense[1:], strict=True):
        d = Pose.from_array(a).between(Pose.from_array(b))
        assert abs(d.y) < 1e-6 or abs(d.theta) < 1e-9 or np.hypot(d.x, d.y) < 1e-9 or b is dense[-1]


def test_backward_steps_are_as_noisy_as_forward_ones():
    noise = OdometryNoise(0.1, 0.05, 0.1, 0.05)
    fwd = sample_increments(Pose(0.1, 0.0, 0.0), noise, np.random.default_rng(2), 20000)
    bwd = sample_increments(Pose(-0.1, 0.0, 0.0), noise, np.random.default_rng(2), 20000)
    np.testing.assert_allclose(np.std(fwd, axis=0), np.std(bwd, axis=0), rtol=0.05)


def test_scan_rate_does_not_change_the_odometry():
    """The 1 Hz sequence's odometry is the 10 Hz trajectory's, sampled (odometry has its own
    rate): over a 1 s gap its increment error is that of ten 0.1 m steps, not one 1 m step."""

    from tfloc.io.scenario import read_scans, read_scenario

    root = SCEN
    err = {}
    for name in ("seq-rate-1hz-b", "seq-easy-b"):
        s = read_scans(read_scenario(root / name))
        if name == "seq-easy-b":
            s = s[::10]
        e = [a.odom.between(b.odom).distance_to(a.true.between(b.true)) for a, b in zip(s[:-1], s[1:], strict=True)]
        err[name] = float(np.median(e))
    # the same order of magnitude (different draws); one 1 m step at α = 0.05 would give ~3× more
    assert 0.5 < err["seq-rate-1hz-b"] / err["seq-easy-b"] < 2.0
