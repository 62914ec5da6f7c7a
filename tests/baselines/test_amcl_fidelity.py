"""Fidelity of the ``amcl`` port to Nav2's own code, compiled in the ``amcl`` wheel (``amcl-wheel``).

* **Step by step**: the port's kernels driven as the wheel drives Nav2's C code (its seeding, its
  motion update on the first scan, beam model, ``pf_err`` 0.01 / ``pf_z`` 3, no update gate) give
  the wheel's particle-set mean bit for bit, update after update, from a spread start: the same
  random numbers, motion model, beam model, KLD resampling and statistics.
* **As trackers**: with the beam model and the wheel's parameters, the port (publishing the
  heaviest cluster's mean, as Nav2) and the wheel (publishing the whole set's mean) track bundled
  sequences with tracked shares and APEs whose 95 % intervals over 10 seeds overlap; the
  whole ``seq-easy-*`` sequences are the ``slow`` comparison (figures: ``docs/baselines/amcl.md``).

Skipped where the wheel is not installed."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from _paths import SCEN
from scipy import stats

pytest.importorskip("amcl")
from tfloc.baselines._amcl_common import amcl_grid  # noqa: E402
from tfloc.baselines.amcl import AmclTracker  # noqa: E402
from tfloc.baselines.amcl.map.map import nav_map  # noqa: E402
from tfloc.baselines.amcl.motion_model.differential_motion_model import differential  # noqa: E402
from tfloc.baselines.amcl.pf import pf  # noqa: E402
from tfloc.baselines.amcl.pf.pf_pdf import new_stream, srand48  # noqa: E402
from tfloc.baselines.amcl.sensors.laser.beam_model import beam_model  # noqa: E402
from tfloc.baselines.amcl.sensors.laser.laser import beam_step  # noqa: E402
from tfloc.baselines.amcl_wheel import AmclWheelTracker, _pdf_seed_counter  # noqa: E402

from tfloc.core.pose import Pose  # noqa: E402
from tfloc.evaluation.trajectory import score_rows  # noqa: E402
from tfloc.harness.track import odom_deltas, track  # noqa: E402
from tfloc.io.scenario import map_for, read_scans, read_scenario  # noqa: E402

SCENARIOS = SCEN
#: the wheel's parameters, which it cannot change (pf_alloc's KLD bounds) or has (the beam model)
WHEEL_PARAMS = {"laser_model_type": "beam", "pf_err": 0.01, "pf_z": 3.0}


def sequence(name: str, n: int | None = None):
    """A bundled sequence dataset: scenario, its first ``n`` scans, its map."""
    sc = read_scenario(SCENARIOS / name)
    scans = read_scans(sc)[:n]
    return sc, scans, map_for(sc, scans[0], {})


def test_the_port_is_the_wheels_filter_bit_for_bit() -> None:
    """100 updates of seq-quick: the port's set mean equals the wheel's ``get_pose_mean`` exactly."""
    sc, scans, vmap = sequence("seq-quick", 100)
    seed = 3
    sig = (0.3, 0.1) if _pdf_seed_counter() is not None else (0.0, 0.0)  # another build: a point start
    wheel = AmclWheelTracker(seed=seed, update_min_d=0.0, update_min_a=0.0, initial_sigma_xy=sig[0],
                             initial_sigma_theta=sig[1])
    wheel.start(vmap, sc.laser, scans[0].initial)
    nav = nav_map(amcl_grid(vmap))
    bearings = np.asarray(sc.laser.angles, dtype=float)
    rmax = sc.laser.max_range
    step = beam_step(bearings.size, 60)
    odom, prev, s, rng = Pose(), None, None, None
    for k, (scan, d) in enumerate(zip(scans, odom_deltas(scans), strict=True)):
        wheel.step(scan.ranges, d, 0.1 * k)
        odom = odom.compose(d)
        pose = odom.as_array()
        if s is None:  # the wheel: pf_init after srand48(seed + 1), then srand48(seed)
            rng = new_stream(seed + 1)
            s = pf.init_gaussian(rng, scans[0].initial.as_array(), np.diag([sig[0] ** 2, sig[0] ** 2, sig[1] ** 2]), 2000)
            srand48(rng, seed)
            prev = pose
        dth = pose[2] - prev[2]
        delta = np.array([pose[0] - prev[0], pose[1] - prev[1], math.atan2(math.sin(dth), math.cos(dth))])
        poses = s.poses.copy()  # the wheel moves the particles on every update, the first included
        differential(rng, poses, pose, delta, 0.2, 0.2, 0.2, 0.2)
        r = np.asarray(scan.ranges, dtype=float)
        r = np.where(np.isfinite(r) & (r < rmax), r, np.inf)
        w = s.weights.copy()
        total = beam_model(poses, w, r, bearings, step, rmax, nav.occ_state, *nav.geometry,
                                  0.5, 0.05, 0.05, 0.5, 0.2, 0.1)
        pf.normalise(w, total, 0.0, 0.0, 0.0, 0.0)
        s, _, _, _ = pf.resample(rng, dataclasses.replace(s, poses=poses, weights=w), 0.0, 0.0, 500, 2000,
                                 0.01, 3.0, nav.free_cells, nav.geometry)
        prev = pose
        m = wheel._filter.get_pose_mean()
        c = np.array(wheel._filter.get_pose_covariance().to_list())
        assert np.array_equal(np.array([m.x, m.y, m.theta]), s.mean), k
        assert np.array_equal(c, s.cov), k


def interval(values: np.ndarray) -> tuple[float, float, float]:
    """Mean and its 95 % t-interval over seeds."""
    v = np.asarray(values, dtype=float)
    half = stats.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v))
    return float(v.mean()), float(v.mean() - half), float(v.mean() + half)


def compare(name: str, n: int | None, seeds: range) -> dict:
    """Tracked share and APE RMSE (m) of the port and the wheel, 95 % intervals over ``seeds``."""
    sc, scans, vmap = sequence(name, n)
    out = {}
    for label, make in (("port", lambda s: AmclTracker(seed=s, **WHEEL_PARAMS)),
                        ("wheel", lambda s: AmclWheelTracker(seed=s))):
        scores = [score_rows(track(sc, scans, make(s), map=vmap)) for s in seeds]
        out[label] = {"tracked": interval([x.tracked for x in scores]),
                      "ape_m": interval([x.ape_rmse_m for x in scores])}
    return out


def agree(result: dict) -> None:
    """Every metric's 95 % intervals overlap."""
    for metric in ("tracked", "ape_m"):
        (_, lo_p, hi_p), (_, lo_w, hi_w) = result["port"][metric], result["wheel"][metric]
        assert lo_p <= hi_w and lo_w <= hi_p, (metric, result)


def report(name: str, n: int | None, seeds: range, result: dict) -> None:
    for label in ("port", "wheel"):
        r = result[label]
        print(f"{name}[:{n}] {label} seeds {seeds.start}-{seeds.stop - 1}: tracked "
              "{:.3f} [{:.3f}, {:.3f}], APE RMSE {:.4f} [{:.4f}, {:.4f}] m".format(*r["tracked"], *r["ape_m"]))


@pytest.mark.parametrize(("name", "n"), [("seq-quick", None),
                                         pytest.param("seq-easy-a", 200, marks=pytest.mark.sweep)])
def test_port_and_wheel_track_alike(name, n) -> None:
    seeds = range(10)
    result = compare(name, n, seeds)
    report(name, n, seeds, result)
    agree(result)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["seq-easy-a", "seq-easy-b", "seq-easy-c"])
def test_port_and_wheel_track_alike_whole_sequences(name) -> None:
    seeds = range(10)
    result = compare(name, None, seeds)
    report(name, None, seeds, result)
    agree(result)
