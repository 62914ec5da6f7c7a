"""Scenario generation: reproducible bytes, strata, free-space poses, maps."""

import filecmp
import math

import numpy as np

from tfloc.core.pose import angdiff
from tfloc.datasets.offices import OFFICES
from tfloc.datasets.protocol import ANGLE_BINS_DEG, DIST_BINS_M
from tfloc.datasets.synthetic import BundleSpec, generate_bundle
from tfloc.io.geojson import read_vector_map
from tfloc.io.scenario import read_scans, read_scenario


def _all_files(root):
    return sorted(p.relative_to(root) for p in root.rglob("*") if p.is_file())


def test_same_seed_same_bytes_other_seed_differs(tmp_path):
    spec = BundleSpec(seed=7, pool_per_cell=2, detail_per_cell=1)
    generate_bundle(tmp_path / "a", spec)
    generate_bundle(tmp_path / "b", spec)
    generate_bundle(tmp_path / "c", BundleSpec(seed=8, pool_per_cell=2, detail_per_cell=1))
    files = _all_files(tmp_path / "a")
    assert files == _all_files(tmp_path / "b") and len(files) == 3 + 4 * 2
    for f in files:
        assert filecmp.cmp(tmp_path / "a" / f, tmp_path / "b" / f, shallow=False), f
    pool = "scenarios/office-pool/scans.csv"
    assert (tmp_path / "a" / pool).read_bytes() != (tmp_path / "c" / pool).read_bytes()


def test_strata_and_free_space(tmp_path):
    generate_bundle(tmp_path, BundleSpec(seed=3, pool_per_cell=3, detail_per_cell=1))
    sc = read_scenario(tmp_path / "scenarios" / "office-pool")
    m = read_vector_map(sc.map_path)
    scans = read_scans(sc)
    assert len(scans) == 27 and sc.laser.n_beams == 181 and sc.laser.max_range == 10.0
    for s in scans:
        i, j = int(s.group[1]) - 1, int(s.group[4]) - 1
        d = s.true.distance_to(s.initial)
        a = math.degrees(abs(angdiff(s.initial.theta, s.true.theta)))
        assert DIST_BINS_M[i][0] < d < DIST_BINS_M[i][1], (s.scan_id, d)
        assert ANGLE_BINS_DEG[j][0] < a < ANGLE_BINS_DEG[j][1], (s.scan_id, a)
        xy = np.array([[s.true.x, s.true.y], [s.initial.x, s.initial.y]])
        assert m.is_free(xy, 0.3).all()
    # noise-free check: the scan is the raycast plus ~1 cm noise
    r = m.raycast(scans[0].true, sc.laser)
    ok = np.isfinite(r) & np.isfinite(scans[0].ranges)
    assert 0.003 < np.std(scans[0].ranges[ok] - r[ok]) < 0.03


def test_office_maps_detail_levels():
    n = [len(OFFICES[k]().segments) for k in (1, 2, 3)]
    assert 60 <= n[0] <= 100 and n[0] < n[1] < n[2]
    free = [OFFICES[k]().is_free(np.array([[10.0, 7.5]]), 0.3)[0] for k in (1, 2, 3)]
    assert all(free)
