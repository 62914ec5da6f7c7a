"""Global-localization datasets: mode, no guesses, poses in free space, regeneration."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from _committed import assert_same_file
from _paths import ROOT, SCEN

from tfloc.core.matcher import check_solvable, get_matcher
from tfloc.core.problem import Problem
from tfloc.datasets.global_sets import (
    DEV_EVERY,
    DEV_SCANS,
    OFFICE_SCANS,
    generate_global_offices,
)
from tfloc.errors import InvalidProblemError
from tfloc.io.geojson import read_vector_map
from tfloc.io.scenario import GLOBAL, map_for, read_scans, read_scenario


@pytest.mark.bitwise
def test_dev_office_sets_regenerate(office_maps) -> None:
    """The same bytes, or on another CPU within the last written digit (tests/_committed.py)."""
    dirs = generate_global_offices(office_maps, n=2, n_dev=DEV_SCANS)
    for d in dirs:
        if d.name.startswith("global-dev-office"):
            for f in ("scenario.json", "scans.csv"):
                assert_same_file(d / f, SCEN / d.name / f)
    # the evaluation sets' first scans too (the generator draws scan by scan)
    for lv in (1, 2, 3):
        mine = (office_maps / "scenarios" / f"global-office-{lv}" / "scans.csv").read_text().splitlines()
        bundled = (SCEN / f"global-office-{lv}" / "scans.csv").read_text().splitlines()
        assert mine[:3] == bundled[:3]


#: corrected scans per real log (every one of them is in exactly one of its two real sets)
REAL_SCANS = {"intel": 910, "csail": 406, "aces": 440}


@pytest.mark.parametrize("name, n_min", [("global-office-1", OFFICE_SCANS), ("global-office-2", OFFICE_SCANS),
                                         ("global-office-3", OFFICE_SCANS),
                                         ("real-intel-global", 728), ("real-csail-global", 324),
                                         ("real-aces-global", 352),
                                         ("global-dev-real-intel", 182), ("global-dev-real-csail", 82),
                                         ("global-dev-real-aces", 88),
                                         ("global-dev-office-2", DEV_SCANS),
                                         ("global-dev-real-csail-sim", DEV_SCANS)])
def test_bundled_global_sets(name, n_min) -> None:
    sc = read_scenario(SCEN / name)
    assert sc.mode == GLOBAL
    scans = read_scans(sc)
    assert len(scans) >= n_min
    assert all(s.initial is None and s.true is not None for s in scans)
    m = map_for(sc, scans[0])
    xy = np.array([[s.true.x, s.true.y] for s in scans])
    assert m.in_bounds(xy).all()
    groups = {s.group for s in scans}
    real = name.startswith("real-") or (name.startswith("global-dev-real-") and not name.endswith("-sim"))
    # a real set holds real scans only, grouped by the fifth of the log they lie in
    assert groups == ({f"real-{q}" for q in range(1, 6)} if real else {"sim"})
    if real:
        return
    assert m.is_free(xy, 0.3).all()  # simulated poses keep their clearance
    headings = np.array([s.true.theta for s in scans])
    if len(scans) >= 50:  # spread over the free space and all headings
        assert np.ptp(xy[:, 0]) > 0.6 * (m.bounds[2] - m.bounds[0])
        assert np.histogram(headings, bins=4, range=(-np.pi, np.pi))[0].min() > 0.1 * len(scans)


@pytest.mark.parametrize("key", sorted(REAL_SCANS))
def test_real_scans_split_into_development_and_held_out(key) -> None:
    """Every corrected scan once: every DEV_EVERY-th in development, the rest held out."""
    held = [s.scan_id for s in read_scans(read_scenario(SCEN / f"real-{key}-global"))]
    dev = [s.scan_id for s in read_scans(read_scenario(SCEN / f"global-dev-real-{key}"))]
    assert sorted(held + dev) == [f"r{k:04d}" for k in range(REAL_SCANS[key])]
    assert dev == [f"r{k:04d}" for k in range(0, REAL_SCANS[key], DEV_EVERY)]


def test_dev_and_evaluation_sets_are_disjoint() -> None:
    for lv in (1, 2, 3):
        ev = {(round(s.true.x, 3), round(s.true.y, 3)) for s in read_scans(read_scenario(SCEN / f"global-office-{lv}"))}
        dev = {(round(s.true.x, 3), round(s.true.y, 3))
               for s in read_scans(read_scenario(SCEN / f"global-dev-office-{lv}"))}
        assert not ev & dev


def test_a_local_matcher_gets_an_invalid_problem_not_a_crash() -> None:
    sc = read_scenario(SCEN / "global-dev-office-1")
    scan = read_scans(sc)[0]
    m = read_vector_map(sc.map_path)
    problem = Problem(m, sc.laser, scan.ranges, scan.initial)
    with pytest.raises(InvalidProblemError, match="solves local problems only"):
        check_solvable(get_matcher("csm-corr"), problem)
    check_solvable(get_matcher("bnb-global"), problem)


@pytest.mark.bitwise
def test_real_global_sets_regenerate(tmp_path) -> None:
    import json

    from tfloc.datasets.global_sets import build_global_real

    (tmp_path / "maps").mkdir()
    for key in ("intel", "csail", "aces"):
        for ext in ("yaml", "pgm"):
            shutil.copy(ROOT / "data" / "maps" / f"real-{key}.{ext}", tmp_path / "maps")
    for d in build_global_real(ROOT / "data" / "real", tmp_path):
        assert_same_file(d / "scans.csv", SCEN / d.name / "scans.csv")
        mine, bundled = (json.loads((p / "scenario.json").read_text()) for p in (d, SCEN / d.name))
        assert mine == bundled, d.name  # the map path too: maps/ sits where it does in data/
