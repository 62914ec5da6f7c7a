"""Map styles (tfloc.maps.styles) on tiny hand-made counts and a tiny synthetic log."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tfloc.core.laser import LaserSpec
from tfloc.io.rosmap import read_ros_map, write_exported_map
from tfloc.maps import styles as st
from tfloc.maps.build import ScanCounts, grid_from_counts, scan_counts
from tfloc.maps.grid import GridMap


def _counts(hits: np.ndarray, passes: np.ndarray | None = None) -> ScanCounts:
    hits = np.asarray(hits, dtype=float)
    passes = np.zeros(hits.shape, dtype=np.int64) if passes is None else np.asarray(passes, dtype=np.int64)
    return ScanCounts(hits, passes, (0.0, 0.0), 0.05)


def _room_log() -> tuple[np.ndarray, np.ndarray, LaserSpec]:
    """Scans of a 4 × 3 m box room from three poses (exact ranges, 360 beams at 1°)."""
    laser = LaserSpec.from_degrees(10.0, 359.0, 1.0, -180.0)
    poses = np.array([[1.0, 1.0, 0.0], [2.0, 1.5, 0.3], [3.0, 2.0, -0.2]])
    ranges = []
    for x, y, th in poses:
        a = th + laser.angles
        c, s = np.cos(a), np.sin(a)
        with np.errstate(divide="ignore"):
            tx = np.where(c > 0, (4.0 - x) / c, np.where(c < 0, -x / c, np.inf))
            ty = np.where(s > 0, (3.0 - y) / s, np.where(s < 0, -y / s, np.inf))
        ranges.append(np.minimum(tx, ty))
    return np.array(ranges), poses, laser


def test_hits_only_ignores_carving_and_needs_two_hits() -> None:
    R, P, laser = _room_log()
    carved = scan_counts(R, P, laser, 0.05, carve=True)
    plain = scan_counts(R, P, laser, 0.05, carve=False)
    assert carved.passes.sum() > 0 and plain.passes.sum() == 0
    a, b = st.hits_only(carved), st.hits_only(plain)
    np.testing.assert_array_equal(a.occupancy, b.occupancy)       # passes change nothing
    np.testing.assert_array_equal(a.occupied, carved.hits >= 2)
    assert not np.isnan(a.occupancy).any() and (a.free == ~a.occupied).all()
    one = _counts([[0, 1, 2, 5]])
    assert st.hits_only(one).occupied[0].tolist() == [False, False, True, True]


@pytest.mark.parametrize("k", [0, 1, 2])
def test_thickening_grows_walls_by_k_cells(k: int) -> None:
    occ = np.zeros((21, 21), dtype=np.float32)
    occ[10, 10] = 1.0                 # a post
    occ[2, 3:18] = 1.0                # a one-cell wall
    g = GridMap(occ, 0.05, (0.0, 0.0), 0.25, 0.1)
    t = st.thickened(g, k)
    jj, ii = np.nonzero(t.occupied[6:15, 6:15])
    assert (jj.max() - jj.min() + 1, ii.max() - ii.min() + 1) == (2 * k + 1, 2 * k + 1)
    assert t.occupied[:, 10].sum() - (2 * k + 1) == 2 * k + 1      # the wall's cross-section
    assert t.occupied[2 - k: 3 + k, 3 - k: 18 + k].all()
    assert t.occupied.sum() == (2 * k + 1) ** 2 + (2 * k + 1) * (15 + 2 * k)
    assert (t.occupancy[g.occupied] == g.occupancy[g.occupied]).all()


def test_incomplete_removes_exactly_the_least_observed_tenth() -> None:
    rng = np.random.default_rng(3)
    hits = rng.integers(1, 40, size=(30, 30)).astype(float)
    passes = rng.integers(0, 5, size=(30, 30))
    hits[rng.random((30, 30)) < 0.6] = 0.0                       # 40 % of the cells are walls
    counts = _counts(hits, passes)
    g = grid_from_counts(counts)
    inc = st.incomplete(g, counts, 0.10)
    n = int(g.occupied.sum())
    gone = g.occupied & ~inc.occupied
    assert gone.sum() == round(0.1 * n) and not (inc.occupied & ~g.occupied).any()
    seen = hits + passes
    assert seen[gone].max() <= seen[inc.occupied].min()          # the least observed went
    assert np.isnan(inc.occupancy[gone]).all()


def test_gmapping_and_cartographer_written_and_read_as_ros_does(tmp_path: Path) -> None:
    hits = np.array([[0, 1, 1, 10, 3, 0]], dtype=float)
    passes = np.array([[0, 9, 2, 0, 20, 60]])
    c = _counts(hits, passes)
    gm = st.gmapping(c)
    assert gm.occupied[0].tolist() == [False, False, True, True, False, False]   # > 25 % of beams
    assert np.isnan(gm.occupancy[0, 0]) and gm.free[0, [1, 4, 5]].all()
    back = read_ros_map(write_exported_map(gm, tmp_path / "g.yaml", "map_saver"))
    np.testing.assert_array_equal(back.occupied, gm.occupied)
    np.testing.assert_array_equal(back.free, gm.free)
    ca = st.cartographer(c)
    # 10 hits: odds 1.22^10 → p 0.88 occupied; 1 hit and 2 misses: p 0.53, grey (unknown in
    # trinary); 60 misses: p 0.1 (clamped) → free; 3 hits and 20 misses: p 0.45, grey
    back = read_ros_map(write_exported_map(ca, tmp_path / "c.yaml", "cartographer"))
    assert back.occupied[0].tolist() == [False, False, False, True, False, False]
    assert back.free[0].tolist() == [False, False, False, False, False, True]
    assert np.isnan(back.occupancy[0, [0, 1, 2, 4]]).all()
    assert "mode" not in (tmp_path / "c.yaml").read_text()
