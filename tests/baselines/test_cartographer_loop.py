"""``cartographer`` (the pure-localization loop): the range data inserter's odds, ActiveSubmaps2D's
turnover, the sampler, the pose optimisation recovering a known offset (and its Jacobian), the
constraint search finding a scan in a frozen submap, the loop along a short simulated sequence,
and bad input as one-line errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _paths import SCEN
from tfloc.baselines.cartographer import CartographerTracker
from tfloc.baselines.cartographer._filters import matched_points
from tfloc.baselines.cartographer._frozen import frozen_submaps, search
from tfloc.baselines.cartographer._optimize import Blocks, _errors, _huber, solve
from tfloc.baselines.cartographer._submaps import ActiveSubmaps, Submap
from tfloc.baselines.cartographer.tracker import _Sampler

from tfloc.core.pose import Pose
from tfloc.errors import InvalidProblemError, ParameterError
from tfloc.harness.track import odom_deltas
from tfloc.io.scenario import map_for, read_scans, read_scenario


def _odds(p: float) -> float:
    return p / (1 - p)


def _p(o: float) -> float:
    return o / (1 + o)


def test_insertion_applies_hit_and_miss_odds_once_per_scan_and_clamps() -> None:
    s = Submap((0.0, 0.0), 0.05)
    wall = np.array([[2.01, 0.01]])
    s.insert(np.zeros(2), wall, np.zeros((0, 2)), 0.55, 0.49, True)
    g = s.grid()
    at = lambda x, y: float(g.probability_at_cells(*g.cells(np.array([[x, y]])))[0])  # noqa: E731
    assert at(2.01, 0.01) == pytest.approx(0.55)  # an unknown cell takes the update's probability
    assert at(1.0, 0.01) == pytest.approx(0.49)  # crossed by the ray: a miss
    assert at(0.0, 1.0) == pytest.approx(0.1)  # never seen: kMinProbability for the matchers
    s.insert(np.zeros(2), wall, np.zeros((0, 2)), 0.55, 0.49, True)
    g = s.grid()
    assert at(2.01, 0.01) == pytest.approx(_p(_odds(0.55) ** 2))
    assert at(1.0, 0.01) == pytest.approx(_p(_odds(0.49) ** 2))
    for _ in range(60):
        s.insert(np.zeros(2), wall, np.zeros((0, 2)), 0.55, 0.49, True)
    g = s.grid()
    assert at(2.01, 0.01) == pytest.approx(0.9) and at(1.0, 0.01) == pytest.approx(0.1)
    # a cell hit by one beam and crossed by another in the same scan takes the hit only
    t = Submap((0.0, 0.0), 0.05)
    t.insert(np.zeros(2), np.array([[1.01, 0.01], [2.01, 0.01]]), np.zeros((0, 2)), 0.55, 0.49, True)
    g = t.grid()
    assert at(1.01, 0.01) == pytest.approx(0.55)
    # a miss frees its end cell; no free space: only hits
    u = Submap((0.0, 0.0), 0.05)
    u.insert(np.zeros(2), np.zeros((0, 2)), np.array([[3.01, 0.01]]), 0.55, 0.49, False)
    assert np.isnan(u.prob).all()


def test_active_submaps_turn_over_as_cartographer() -> None:
    a = ActiveSubmaps(3, 0.05)
    pts = np.array([[1.0, 0.0]])
    seen = []
    for k in range(10):
        subs, finished = a.insert(np.array([0.1 * k, 0.0]), pts, np.zeros((0, 2)), 0.55, 0.49, True)
        seen.append(([s.num_range_data for s in subs], finished))
    assert [n for n, _ in seen[:4]] == [[1], [2], [3], [4, 1]]
    assert seen[5] == ([6, 3], True)  # the older finished at 2·num_range_data
    assert seen[6][0] == [4, 1]  # a third submap: the finished one leaves the active pair
    assert a.submaps[0].origin_xy == pytest.approx((0.6, 0.0))  # the third submap, started at scan 7


def test_fixed_ratio_sampler_pulses_at_its_ratio_from_the_first() -> None:
    s = _Sampler(0.3)
    pulses = [s.pulse() for _ in range(100)]
    assert pulses[0] and not pulses[1] and sum(pulses) == 30


def _chain(offset: Pose, outlier: bool):
    truth = [Pose(0.1 * k, 0.002 * k * k, 0.03 * k) for k in range(40)]
    x0 = np.array([offset.compose(p).as_array() for p in truth])
    rows = [(k, np.zeros(3), k + 1, truth[k].inverse().compose(truth[k + 1]).as_array(), 1e5, 1e5, False)
            for k in range(39)]
    frozen = Pose(1.0, 0.5, 0.2)
    rows += [(-1, frozen.as_array(), k, frozen.inverse().compose(truth[k]).as_array(), 1.1e4, 1e5, True)
             for k in range(0, 40, 3)]
    if outlier:
        rows.append((-1, frozen.as_array(), 20, frozen.inverse().compose(Pose(5, 5, 1)).as_array(), 1.1e4, 1e5,
                     True))
    c = list(zip(*rows, strict=True))
    b = Blocks(np.array(c[0]), np.array(c[1], float), np.array(c[2]), np.array(c[3], float), np.array(c[4], float),
               np.array(c[5], float), np.array(c[6], bool))
    return truth, x0, b


def test_optimisation_recovers_a_known_offset_despite_an_outlier() -> None:
    truth, x0, b = _chain(Pose(0.3, -0.2, 0.05), outlier=True)
    x, info = solve(x0, b, 10.0, 50)
    err = np.abs(x - np.array([p.as_array() for p in truth]))
    assert err[:, :2].max() < 1e-3 and err[:, 2].max() < 1e-3
    assert np.abs(x0 - np.array([p.as_array() for p in truth]))[:, :2].max() > 0.2  # it had to move


def test_robust_residual_jacobian_matches_central_differences() -> None:
    _, x0, b = _chain(Pose(0.3, -0.2, 0.05), outlier=True)

    def res(v: np.ndarray) -> np.ndarray:
        r, _, _ = _errors(v.reshape(-1, 3), b)
        g, _ = _huber(r, b.robust, 10.0)
        return (g[:, None] * r).ravel()

    r, jE, jS = _errors(x0, b)
    _, M = _huber(r, b.robust, 10.0)
    jE = M @ jE
    h = 1e-7
    for blk in (39, 45):  # an inter (robust, outlier regime) and a consecutive block
        end = b.end[blk]
        for d in range(3):
            v = x0.copy()
            v[end, d] += h
            w = x0.copy()
            w[end, d] -= h
            num = (res(v.ravel()) - res(w.ravel()))[3 * blk:3 * blk + 3] / (2 * h)
            assert np.allclose(num, jE[blk, :, d], rtol=1e-4, atol=1e-2)


@pytest.fixture(scope="module")
def quick():
    sc = read_scenario(SCEN / "seq-quick")
    scans = read_scans(sc)
    return sc, scans, map_for(sc, scans[0], {})


def test_constraint_search_finds_a_scan_in_its_frozen_submap(quick) -> None:
    sc, scans, m = quick
    s = scans[30]
    pts = matched_points(sc.laser.to_points(s.ranges), min_range=0, max_range=30, voxel_size=0.025,
                         max_length=0.5, min_num_points=200, adaptive_max_range=50)
    guess = Pose(s.true.x + 0.6, s.true.y - 0.4, s.true.theta + math.radians(8))
    found = [search(f, pts, guess, 7.0, math.radians(30), 0.55) for f in frozen_submaps(m, 20.0, 7)]
    best = max((h for h in found if h is not None), key=lambda h: h[1])
    assert best[1] > 0.8
    assert math.hypot(best[0].x - s.true.x, best[0].y - s.true.y) < 0.06
    assert abs(math.remainder(best[0].theta - s.true.theta, 2 * math.pi)) < math.radians(1)


def test_the_loop_tracks_a_short_simulated_sequence(quick) -> None:
    """seq-quick's first 60 scans from the start pose; with the start as a connection to the map
    (the sensitivity reading: the first full-submap search lands in the wrong tile here)."""
    sc, scans, m = quick
    t = CartographerTracker(start_connected=True)
    t.start(m, sc.laser, scans[0].initial)
    errs = []
    for s, d in zip(scans[:60], odom_deltas(scans[:60]), strict=True):
        e = t.step(s.ranges, d, s.stamp, "t")
        errs.append(math.hypot(e.pose.x - s.true.x, e.pose.y - s.true.y))
    assert t.optimisations >= 1 and len(t._inter) > 0
    assert np.median(errs) < 0.1 and max(errs) < 0.3
    # dead reckoning from the same start is worse
    p, dr = scans[0].initial, []
    for s, d in zip(scans[:60], odom_deltas(scans[:60]), strict=True):
        p = p.compose(d)
        dr.append(math.hypot(p.x - s.true.x, p.y - s.true.y))
    assert np.mean(errs[40:]) < np.mean(dr[40:])


def test_bad_input_is_one_line(quick) -> None:
    sc, scans, m = quick
    with pytest.raises(ParameterError, match="hit_probability"):
        CartographerTracker(hit_probability=1.5)
    with pytest.raises(ParameterError):
        CartographerTracker(no_such_key=1)
    t = CartographerTracker()
    with pytest.raises(RuntimeError):
        t.step(scans[0].ranges, Pose(), 0.0)
    with pytest.raises(InvalidProblemError, match="not finite"):
        t.start(m, sc.laser, Pose(math.nan, 0.0, 0.0))
    t.start(m, sc.laser, scans[0].initial)
    with pytest.raises(InvalidProblemError, match="ranges, expected"):
        t.step(scans[0].ranges[:-3], Pose(), 0.0, "scans.csv:2")
    with pytest.raises(InvalidProblemError, match="not finite"):
        t.step(scans[0].ranges, Pose(math.inf, 0.0, 0.0), 0.0, "scans.csv:2")
