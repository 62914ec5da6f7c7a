"""tfloc amcl-params: the odometry's α and the scanner's sigma_hit measured from a recording."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _paths import ROOT

import tfloc
from tfloc.cli import main
from tfloc.core.pose import Pose
from tfloc.datasets.motion import OdometryNoise, sample_increments
from tfloc.evaluation.motion_fit import fit_motion_noise, fit_sigma_hit, update_intervals


def _walk(n: int, rng: np.random.Generator) -> list[Pose]:
    """A walk of steps 0.1–0.6 m turning up to ±0.8 rad, some of them turns in place."""
    poses, p = [Pose()], Pose()
    for k in range(n):
        step = Pose(0.0, 0.0, rng.uniform(-0.8, 0.8)) if k % 5 == 0 else \
            Pose(rng.uniform(0.1, 0.6), rng.uniform(-0.05, 0.05), rng.uniform(-0.5, 0.5))
        p = p.compose(step)
        poses.append(p)
    return poses


def test_the_alphas_that_drew_the_odometry_are_found_again():
    rng = np.random.default_rng(4)
    truth = _walk(4000, rng)
    noise = OdometryNoise(0.05, 0.02, 0.03, 0.01)
    odom = [Pose()]
    for a, b in zip(truth[:-1], truth[1:], strict=True):   # one draw per interval, as the model says
        odom.append(odom[-1].compose(Pose.from_array(sample_increments(a.between(b), noise, rng)[0])))
    fit = fit_motion_noise(odom, truth, 0.0, 0.0)
    assert fit.intervals == 4000
    got = np.array([fit.alpha1, fit.alpha2, fit.alpha3, fit.alpha4])
    assert got == pytest.approx(noise.alphas, rel=0.35)


def test_intervals_follow_nav2s_gate_and_skip_rows_without_truth():
    odom = [Pose(0.1 * k, 0.0, 0.0) for k in range(10)]
    truth = [p if k % 2 == 0 else None for k, p in enumerate(odom)]
    assert update_intervals(odom, truth, 0.25, 0.2) == [(0, 4), (4, 8)]
    with pytest.raises(ValueError, match="too few"):
        fit_motion_noise(odom, truth, 0.25, 0.2)


def test_sigma_hit_is_the_returns_spread_around_the_map():
    room = tfloc.load_map(ROOT / "data" / "maps" / "test-room.geojson")
    laser = tfloc.LaserSpec.lms200()
    rng = np.random.default_rng(5)
    poses = [Pose(2.0 + 0.3 * k, 2.0, 0.4 * k) for k in range(6)]
    scans = [room.raycast(p, laser) + rng.normal(0.0, 0.02, laser.n_beams) for p in poses]
    sigma, n = fit_sigma_hit(room, laser, scans, poses)
    assert n > 500 and 0.012 < sigma < 0.024


def test_the_command_prints_a_nav2_block(capsys):
    assert main(["amcl-params", "--dataset", str(ROOT / "data" / "scenarios" / "real-csail-native"),
                 "--hit-scans", "20"]) == 0
    out = capsys.readouterr().out
    assert "ros__parameters:" in out and "alpha1:" in out and "sigma_hit:" in out
    assert 'name = "amcl"' in out and math.isfinite(float(out.split("sigma_hit:")[1].split()[0]))
