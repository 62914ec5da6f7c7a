"""Baseline ``karto``: bad parameters;
the map's virtual scans. Skipped where karto-scanmatcher has no wheel (Python ≥ 3.12)."""

from __future__ import annotations

import math

import _baseline_cases as cases
import numpy as np
import pytest
from _baseline_cases import make_problem
from tfloc.baselines._scan_lattice import ring_laser, scan_lattice

import tfloc

pytest.importorskip("karto_scanmatcher")
from tfloc.baselines.karto import KartoMatcher  # noqa: E402


def test_score_is_minus_the_response() -> None:
    problem, true = make_problem()
    assert -1.0 <= KartoMatcher().score(problem, true) <= 0.0


def test_registered_name_and_bad_parameters() -> None:
    matcher = tfloc.get_matcher("karto")
    assert isinstance(matcher, KartoMatcher) and matcher.name == "karto"
    for bad in ({"no_such_option": 1}, {"coarse_search_size": 7.05},   # not whole cells of 0.1 m
                {"fine_search_size": 0.31},                            # an odd number of cells
                {"fine_resolution": 0.0}, {"range_threshold": -1.0}, {"base_radius": 0.0}):
        with pytest.raises(tfloc.MatcherError, match="karto"):
            tfloc.get_matcher("karto", **bad)


def test_range_threshold_is_the_lasers_range() -> None:
    problem, _ = make_problem()
    matcher = KartoMatcher()
    matcher.localize(problem)
    assert {key[3] for key in matcher._wrappers} == {problem.laser.max_range}


def test_lattice_scans_are_free_and_match_the_map() -> None:
    m = cases.test_map()
    lattice = scan_lattice(m, 1.0, 0.2, 10.0, 0.25)
    assert len(lattice.positions) > 5
    assert m.is_free(lattice.positions, 0.2).all()
    assert lattice.laser.n_beams == 1440 and math.isclose(lattice.laser.angle_min, -math.pi)
    idx = lattice.near(lattice.positions[0], 1.5)
    assert 0 in idx and np.all(np.hypot(*(lattice.positions[idx] - lattice.positions[0]).T) <= 1.5)
    r = lattice.ranges(idx[:2])
    pose = tfloc.Pose(*lattice.positions[idx[0]], 0.0)
    assert np.allclose(r[0], m.raycast(pose, ring_laser(10.0, 0.25)))
    assert scan_lattice(m, 1.0, 0.2, 10.0, 0.25) is lattice  # cached per map
