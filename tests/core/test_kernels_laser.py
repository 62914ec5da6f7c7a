"""``LaserSpec.to_points`` with cached beam directions against the plain numpy formula (Eq. 4)."""

from __future__ import annotations

import numpy as np
import pytest

from tfloc.core.laser import LaserSpec


def _reference(laser: LaserSpec, r: np.ndarray, keep_invalid: bool) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        pts = np.column_stack((np.cos(laser.angles) * r, np.sin(laser.angles) * r))
        ok = np.isfinite(r) & (r > 0.0) & (r < laser.max_range)
    if keep_invalid:
        pts[~ok] = np.nan
        return pts
    return pts[ok]


@pytest.mark.parametrize("laser", [LaserSpec.lms200(), LaserSpec.from_degrees(30.0, 360.0, 0.5)])
@pytest.mark.parametrize("keep_invalid", [False, True])
def test_to_points_matches_reference(laser, keep_invalid):
    rng = np.random.default_rng(1)
    for _ in range(20):
        r = rng.uniform(-1.0, laser.max_range * 1.2, laser.n_beams)
        r[rng.random(laser.n_beams) < 0.1] = np.inf
        r[rng.random(laser.n_beams) < 0.05] = np.nan
        r[rng.random(laser.n_beams) < 0.05] = laser.max_range
        got = laser.to_points(r, keep_invalid)
        np.testing.assert_array_equal(got, _reference(laser, r, keep_invalid))
    assert laser.to_points(np.full(laser.n_beams, np.inf)).shape == (0, 2)


def test_directions_are_cached_and_read_only():
    laser = LaserSpec.lms200()
    d = laser.directions
    assert d is laser.directions and d.shape == (181, 2) and not d.flags.writeable
    np.testing.assert_allclose(np.hypot(d[:, 0], d[:, 1]), 1.0)


@pytest.mark.parametrize(("laser", "k", "beams"), [(LaserSpec.from_degrees(50.0, 180.0, 0.5), 2, 181),
                                                   (LaserSpec.from_degrees(50.0, 179.0, 1.0), 2, 90),
                                                   (LaserSpec.from_degrees(30.0, 360.0, 0.25), 3, 481),
                                                   (LaserSpec.lms200(), 1, 181)])
def test_every_kth_beam_is_a_scanner_of_those_beams(laser, k, beams):
    thin = laser.every(k)
    assert thin.n_beams == beams == len(range(0, laser.n_beams, k))
    assert np.allclose(thin.angles, laser.angles[::k], rtol=0.0, atol=1e-12)
    assert thin.max_range == laser.max_range and (k > 1 or thin is laser)


def test_a_problem_on_every_kth_beam(test_room):
    from tfloc import InvalidProblemError, Pose, Problem

    laser = LaserSpec.from_degrees(10.0, 180.0, 0.5)
    ranges = test_room.raycast(Pose(3, 3.5, 0), laser)
    p = Problem(test_room, laser, ranges, Pose(3, 3.2, 0.1), where="f:3")
    thin = p.every(2)
    assert thin.laser == laser.every(2) and thin.initial == p.initial and thin.where == "f:3"
    assert thin.ranges.tobytes() == ranges[::2].tobytes() and thin.ranges.flags.c_contiguous
    odd_only = np.where(np.arange(laser.n_beams) % 2 == 1, ranges, np.inf)   # returns on odd beams
    with pytest.raises(InvalidProblemError, match="f:3: scan has no return"):
        Problem(test_room, laser, odd_only, p.initial, where="f:3").every(2)
