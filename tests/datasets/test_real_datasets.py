"""The real-log datasets: the Intel beam-spacing decision, reproducibility of the committed
datasets and maps, and sanity of their ground truth against the data."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _committed import assert_same_file
from _paths import ROOT

from tfloc.core.pose import angdiff
from tfloc.datasets import relations, spacing
from tfloc.datasets.real import (
    ACES_LASER,
    ACES_NO_RETURN_M,
    INTEL_LASER,
    NO_RETURN_M,
    build_all,
    clean_ranges,
)
from tfloc.datasets.relations import build_relations, overlap
from tfloc.io.carmen import read_carmen
from tfloc.io.scenario import map_for, read_scans, read_scenario

DATA = ROOT / "data"
SCEN = DATA / "scenarios"


@pytest.mark.parametrize(("log_file", "no_return", "laser"), [
    ("intel/intel-corrected.log.gz", NO_RETURN_M, INTEL_LASER),
    ("aces/aces-corrected.log.gz", ACES_NO_RETURN_M, ACES_LASER),
], ids=["intel", "aces"])
def test_spacing_decision_recomputed_on_a_subset(log_file: str, no_return: float, laser) -> None:
    """data/real/{intel,aces}/SPACING.md: 1° from -90° lines the corrected scans up best."""
    log = read_carmen(DATA / "real" / log_file)
    R = np.vstack([clean_ranges(s.ranges, no_return) for s in log.lasers[:300]])
    P = log.poses()[:300]
    scores = spacing.compare(R, P, spacing.intel_candidates(50.0))
    assert scores[0].label == "1deg-from-90"
    assert scores[0].laser == laser
    assert scores[0].mean_clipped < 0.97 * scores[1].mean_clipped


@pytest.fixture(scope="module")
def rebuilt(tmp_path_factory) -> Path:
    """The real datasets rebuilt, but for the perturbed relations (written unperturbed here, and
    not compared: drawing their initial poses tests free space in 1172 scan maps, a minute on its
    own; :func:`rebuilt_perturbed` makes them, in ``make bench``'s sweeps)."""
    out = tmp_path_factory.mktemp("real")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(relations, "perturbed", lambda rows, laser, cfg: rows)
        build_relations(DATA / "real", out)
    build_all(DATA / "real", out)
    return out


@pytest.fixture(scope="module")
def rebuilt_perturbed(tmp_path_factory) -> Path:
    """Both relations datasets rebuilt as ``tfloc real-data`` builds them."""
    out = tmp_path_factory.mktemp("real-perturbed")
    build_relations(DATA / "real", out)
    return out


def _sweep(rel: str):
    return pytest.param(rel, marks=pytest.mark.sweep)


@pytest.mark.parametrize("rel", [
    "scenarios/real-csail-relations/scans.csv", "scenarios/real-csail-relations/scenario.json",
    _sweep("scenarios/real-csail-relations-perturbed/scans.csv"),
    _sweep("scenarios/real-csail-relations-perturbed/scenario.json"),
    "scenarios/real-intel-scan-to-map/scans.csv", "scenarios/real-intel-scan-to-map/scenario.json",
    "scenarios/real-csail-scan-to-map/scans.csv", "scenarios/real-csail-scan-to-map/scenario.json",
    "scenarios/real-aces-scan-to-map/scans.csv", "scenarios/real-aces-scan-to-map/scenario.json",
    "maps/real-intel.yaml", "maps/real-intel.pgm", "maps/real-csail.yaml", "maps/real-csail.pgm",
    "maps/real-aces.yaml", "maps/real-aces.pgm",
])
@pytest.mark.bitwise
def test_committed_datasets_are_reproducible(request, rel: str) -> None:
    """The same bytes, or on another CPU within the last written digit (tests/_committed.py)."""
    rebuilt = request.getfixturevalue("rebuilt_perturbed" if "perturbed" in rel else "rebuilt")
    if rel.endswith("scenario.json"):  # the map path is relative to where it was written
        a, b = (json.loads(p.read_text()) for p in (rebuilt / rel, DATA / rel))
        a.pop("map"), b.pop("map")
        assert a == b
    else:
        assert_same_file(rebuilt / rel, DATA / rel)


def test_relations_dataset_matches_the_log() -> None:
    sc = read_scenario(SCEN / "real-csail-relations")
    scans = read_scans(sc)
    assert len(scans) == 1172 and sc.laser.n_beams == 361
    assert all(s.ref_ranges is not None for s in scans)
    assert {s.group for s in scans} == {"local", "loop", "local-no-overlap", "loop-no-overlap"}
    no_overlap = np.array([s.group.endswith("no-overlap") for s in scans])
    assert 40 <= no_overlap.sum() <= 80  # revisits seen from elsewhere; 2 consecutive pairs
    T = np.array([s.true.as_array() for s in scans])
    I0 = np.array([s.initial.as_array() for s in scans])
    de = np.hypot(*(T[:, :2] - I0[:, :2]).T)
    local = np.array([s.group.startswith("local") for s in scans])
    # odometry is a good guess between nearby scans and a poor one across loops
    assert np.median(de[local]) < 0.06 and np.median(de[~local]) > 1.0
    # the reference scan drawn as a polyline agrees with the current scan at the true relation
    # better than at the odometry guess
    gain = []
    for s in scans[:60]:
        m = map_for(sc, s)
        errs = []
        for pose in (s.true, s.initial):
            sim = m.raycast(pose, sc.laser)
            ok = sc.laser.valid(s.ranges) & np.isfinite(sim)
            errs.append(np.median(np.abs(sim - s.ranges)[ok]))
        gain.append(errs[1] - errs[0])
    assert np.median(gain) > 0.0


@pytest.mark.parametrize("name, n", [("real-intel-scan-to-map", 910), ("real-csail-scan-to-map", 406),
                                     ("real-aces-scan-to-map", 440)])
def test_scan_to_map_dataset(name: str, n: int) -> None:
    sc = read_scenario(SCEN / name)
    scans = read_scans(sc)
    grid = map_for(sc, scans[0])
    assert len(scans) == n
    T = np.array([s.true.as_array() for s in scans])
    I0 = np.array([s.initial.as_array() for s in scans])
    # the map agrees with the scans at their corrected poses to a few cm
    R = np.vstack([s.ranges for s in scans])
    sim = grid.raycast(T, sc.laser)
    ok = sc.laser.valid(R) & np.isfinite(sim)
    assert np.median(np.abs(sim - R)[ok]) < 0.04
    # initial poses: free, in bounds, in their bins, balanced
    assert grid.is_free(I0[:, :2], 0.2).all()
    d = np.hypot(*(T[:, :2] - I0[:, :2]).T)
    a = np.degrees(np.abs(angdiff(T[:, 2], I0[:, 2])))
    for s, di, ai in zip(scans, d, a, strict=True):
        i, j = int(s.group[1]), int(s.group[4])
        assert i - 1 <= di < i and 5 * (j - 1) <= ai < 5 * j, s.scan_id
    counts = np.unique([s.group for s in scans], return_counts=True)[1]
    assert len(counts) == 9 and counts.max() - counts.min() <= 1


def test_perturbed_relations_are_in_the_protocol_bins_and_in_the_reference_area() -> None:
    sc = read_scenario(SCEN / "real-csail-relations-perturbed")
    odo = {s.scan_id: s for s in read_scans(read_scenario(SCEN / "real-csail-relations"))}
    scans = read_scans(sc)
    assert [s.scan_id for s in scans] == list(odo) and all(s.true == odo[s.scan_id].true for s in scans)
    T = np.array([s.true.as_array() for s in scans])
    I0 = np.array([s.initial.as_array() for s in scans])
    d = np.hypot(*(T[:, :2] - I0[:, :2]).T)
    a = np.degrees(np.abs(angdiff(I0[:, 2], T[:, 2])))
    cells = np.floor(d).astype(int) * 3 + np.floor(a / 5).astype(int)
    assert cells.min() == 0 and cells.max() == 8
    assert np.bincount(cells).min() >= 1172 // 9 - 1   # balanced
    for s in scans[:50]:
        m = map_for(sc, s)
        assert m.in_bounds(s.initial.xy[None])[0]


def test_overlap_of_a_scan_with_itself_and_with_a_distant_view(lms200) -> None:
    from tfloc.core.pose import Pose

    room = tfloc_room()
    a = room.raycast(Pose(2.0, 2.0, 0.0), lms200)
    assert overlap(a, a, Pose(), lms200) == 1.0
    assert overlap(a, a, Pose(30.0, 0.0, 0.0), lms200) == 0.0


def tfloc_room():
    from tfloc.io.maps import load_map

    return load_map(DATA / "maps" / "test-room.geojson")
