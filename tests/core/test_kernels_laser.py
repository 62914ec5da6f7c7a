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
