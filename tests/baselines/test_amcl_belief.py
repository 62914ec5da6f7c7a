"""AMCL's read-only belief accessors (the weighed particles, the sensor factor at any pose, the last
motion update) leave its answers unchanged; the belief's summary on hand-made particle sets; and
``tfloc track --draw-at/--figure/--explain``, its one-line errors included."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _paths import ROOT
from tfloc.baselines.amcl import AmclTracker

from tfloc.cli import main
from tfloc.core.pose import Pose
from tfloc.evaluation.belief import Snapshot, motion_noise, summarize
from tfloc.io.scenario import Scan, read_scans, read_scenario, write_scenario

QUICK = ROOT / "data" / "scenarios" / "seq-quick"


@pytest.fixture(scope="module")
def quick():
    sc = read_scenario(QUICK)
    return sc, read_scans(sc)[:40]


def steps(tracker: AmclTracker, sc, scans, look: bool = False) -> list:
    """Run ``tracker`` along ``scans``; with ``look``, read every accessor after every step."""
    from tfloc.harness.track import odom_deltas
    from tfloc.io.maps import load_map

    tracker.start(load_map(sc.map_path), sc.laser, scans[0].initial)
    out = []
    for s, d in zip(scans, odom_deltas(scans), strict=True):
        out.append(tracker.step(s.ranges, d, s.stamp))
        if look:
            b = tracker.belief()
            tracker.likelihood(b[0])
            tracker.likelihood(np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]))
            tracker.last_motion()
    return out


def test_the_accessors_leave_the_answers_unchanged(quick) -> None:
    sc, scans = quick
    plain = steps(AmclTracker(seed=3), sc, scans)
    looked = steps(AmclTracker(seed=3), sc, scans, look=True)
    assert [e.pose for e in plain] == [e.pose for e in looked]
    assert [e.info for e in plain] == [e.info for e in looked]


def test_belief_is_the_weighed_set_and_likelihood_its_factors(quick) -> None:
    sc, scans = quick
    tracker = AmclTracker(seed=1)
    assert tracker.belief() is None and tracker.last_motion() is None
    with pytest.raises(RuntimeError, match="before the first filter update"):
        AmclTracker().likelihood(np.zeros((1, 3)))
    ests = steps(tracker, sc, scans)
    assert sum(e.info["updated"] for e in ests) > 3   # the belief is the last update's, whichever scan
    poses, weights = tracker.belief()
    assert poses.shape == (len(weights), 3) and math.isclose(weights.sum(), 1.0, rel_tol=1e-12)
    p = tracker.likelihood(poses)       # resampled every update: the weights before were uniform
    assert np.allclose(weights, p / p.sum(), rtol=1e-12) and (p >= 1.0).all()
    poses[:] = 0.0                       # a copy
    assert not np.array_equal(tracker.belief()[0], poses)


def test_last_motion_is_the_odometry_plus_the_models_noise(quick) -> None:
    sc, scans = quick
    still = AmclTracker(seed=1, alpha1=0.0, alpha2=0.0, alpha3=0.0, alpha4=0.0)
    steps(still, sc, scans)
    before, after, inc = still.last_motion()
    assert math.hypot(inc.x, inc.y) > 0.01       # the gate: a move of more than 1 cm
    assert np.abs(motion_noise(before, after, inc)).max() < 1e-9
    noisy = AmclTracker(seed=1)
    steps(noisy, sc, scans)
    n = motion_noise(*noisy.last_motion())
    assert np.sqrt(np.mean(n[:, 0] ** 2 + n[:, 1] ** 2)) > 0.005


def test_motion_noise_of_hand_made_particles() -> None:
    before = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, math.pi / 2]])
    inc, noise = Pose(1.0, 0.0, 0.1), Pose(0.03, -0.02, 0.01)
    after = np.array([Pose.from_array(b).compose(inc).compose(noise).as_array() for b in before])
    assert np.allclose(motion_noise(before, after, inc), [noise.as_array()] * 2, atol=1e-12)


ORIGIN = Pose()


def snap(particles: np.ndarray, weights: np.ndarray, truth: Pose | None = ORIGIN) -> Snapshot:
    factors = 1.0 + weights * 10
    probes = (("truth", truth, 5.0),) if truth is not None else ()
    return Snapshot(3, "s3", Pose(0.1, 0.0, 0.0), truth, np.ones(3), np.zeros(3), {}, particles, weights,
                    factors, probes)


def test_summary_of_hand_made_particle_sets() -> None:
    n = 100
    p = np.zeros((n, 3))
    p[50:, 0] = 2.0                                         # half of them 2 m away
    uniform = summarize(snap(p, np.full(n, 1.0 / n)))
    assert uniform.ess == pytest.approx(n) and uniform.max_weight_x_mean == pytest.approx(1.0)
    assert uniform.weight_near_truth == pytest.approx(0.5) and uniform.spread_xy_m == pytest.approx(1.0)
    assert uniform.spread_theta_deg == pytest.approx(0.0, abs=1e-6) and uniform.factor == {"truth": 5.0}
    assert uniform.above_truth == 0.0 and math.isnan(uniform.motion_xy_m)
    w = np.zeros(n)
    w[7] = 1.0
    one = summarize(snap(p, w))
    assert one.ess == pytest.approx(1.0) and one.max_weight_x_mean == pytest.approx(n) and one.factor_max == 11.0
    assert math.isnan(summarize(snap(p, w, truth=None)).weight_near_truth)  # no truth: not known
    assert summarize(Snapshot(0, "s", Pose(), None, np.ones(1), np.zeros(1), {})) is None


# -- tfloc track --draw-at ---------------------------------------------------------------------
def _copy(root: Path, n: int, start_off: Pose | None = None, blank_truth: bool = False) -> Path:
    sc = read_scenario(QUICK)
    scans = read_scans(sc)[:n]
    s0 = scans[0]
    first = s0.initial.compose(start_off) if start_off is not None else s0.initial
    scans = [Scan(s.scan_id, s.group, s.ranges, first if k == 0 else None, None if blank_truth else s.true,
                  stamp=s.stamp, odom=s.odom) for k, s in enumerate(scans)]
    return write_scenario(root, "q", sc.map_path, sc.laser, scans, mode="sequence")


def test_cli_draws_and_explains_a_scan(tmp_path, capsys) -> None:
    root = _copy(tmp_path / "a", 30)
    ids = [s.scan_id for s in read_scans(read_scenario(root))]
    fig = tmp_path / "figs" / "b.png"
    assert main(["track", "--dataset", str(root), "--matcher", "amcl", "--out", str(tmp_path / "e.csv"),
                 "--draw-at", ids[20], "--figure", str(fig), "--explain"]) == 0
    out = capsys.readouterr().out
    assert f"scan {ids[20]} (#20)" in out and "effective sample size" in out and "p at truth" in out
    assert "noise added per particle" in out
    assert fig.stat().st_size > 10_000 and fig.read_bytes()[:4] == b"\x89PNG"
    assert main(["track", "--dataset", str(root), "--matcher", "odometry", "--out", str(tmp_path / "e.csv"),
                 "--draw-at", ids[3], "--figure", str(tmp_path / "o.svg"), "--explain"]) == 0
    assert "the tracker exposes none" in capsys.readouterr().out and (tmp_path / "o.svg").exists()


def test_cli_draws_the_first_loss(tmp_path, capsys) -> None:
    root = _copy(tmp_path / "a", 10, start_off=Pose(1.0, 0.0, 0.0))   # started 1 m off: lost at once
    assert main(["track", "--dataset", str(root), "--matcher", "odometry", "--out", str(tmp_path / "e.csv"),
                 "--draw-at", "first-loss", "--explain"]) == 0
    assert "(#0)" in capsys.readouterr().out
    good = _copy(tmp_path / "b", 5)    # dead reckoning stays within 10° for the first scans
    assert main(["track", "--dataset", str(good), "--matcher", "odometry", "--out", str(tmp_path / "e.csv"),
                 "--draw-at", "first-loss", "--explain"]) == 0
    assert "no scan with truth was lost" in capsys.readouterr().err


@pytest.mark.parametrize(("extra", "message"), [
    (["--draw-at", "nope", "--explain"], "--draw-at nope: no such scan_id"),
    (["--figure", "x.png"], "--figure needs --draw-at"),
    (["--explain"], "--explain needs --draw-at"),
    (["--draw-at", "FIRST"], "give --figure PATH and/or --explain"),
    (["--draw-at", "FIRST", "--figure", "x.txt"], "--figure x.txt: the picture's name must end in"),
])
def test_cli_draw_options_one_line_errors(tmp_path, capsys, extra, message) -> None:
    root = _copy(tmp_path / "a", 5)
    first = read_scans(read_scenario(root))[0].scan_id
    extra = [first if a == "FIRST" else a for a in extra]
    assert main(["track", "--dataset", str(root), "--matcher", "odometry", "--out", str(tmp_path / "e.csv"),
                 *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_cli_first_loss_needs_truth(tmp_path, capsys) -> None:
    root = _copy(tmp_path / "a", 5, blank_truth=True)
    assert main(["track", "--dataset", str(root), "--matcher", "odometry", "--out", str(tmp_path / "e.csv"),
                 "--draw-at", "first-loss", "--explain"]) == 2
    err = capsys.readouterr().err
    assert "--draw-at first-loss" in err and "no truth" in err and len(err.strip().splitlines()) == 1
