"""The scaling study (scripts/scaling.py): tiling, the same scans at every size, the slope fits,
and the study end to end on a tiny configuration."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import shapely

from tfloc.core.laser import LaserSpec
from tfloc.datasets.tiling import Tiling, tile_vector_map, tiling_for_area
from tfloc.errors import ConfigError
from tfloc.evaluation.scaling import fit_loglog, level_table, slope_table
from tfloc.io.geojson import read_vector_map
from tfloc.maps.build import rasterize
from tfloc.maps.vector import VectorMap

ROOT = Path(__file__).resolve().parents[1]
OFFICE = ROOT / "data" / "maps" / "office-1.geojson"


def _study():
    spec = importlib.util.spec_from_file_location("scaling_study", ROOT / "scripts" / "scaling.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up there
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def tile():
    return read_vector_map(OFFICE)


def test_tiling_for_area_picks_square_counts(tile):
    n = [tiling_for_area(tile, a).nx for a in (300, 1200, 5000, 20000)]
    assert n == [1, 2, 4, 8]
    t = tiling_for_area(tile, 20000)
    assert t.ny == t.nx and 15000 < t.extent_m2 < 25000
    with pytest.raises(ConfigError):
        tiling_for_area(tile, -1)


def test_tiling_keeps_every_wall_times_the_tiles(tile):
    t = Tiling(3, 2, 25.0, 20.0)
    big = tile_vector_map(tile, t)
    assert len(big.walls) == 6 * len(tile.walls)
    assert len(big.obstacles) == 6 * len(tile.obstacles)
    assert len(big.segments) == 6 * len(tile.segments)
    assert len(shapely.get_parts(big.outline)) == 6
    assert big.outline.area == pytest.approx(6 * tile.outline.area)
    # tile (0, 0) is the original, unmoved; the last one is moved by the pitch
    k = len(VectorMap(walls=tile.walls).segments)
    np.testing.assert_array_equal(big.segments[:k], tile.segments[:k])
    x0, y0, x1, y1 = big.bounds
    tx0, ty0, tx1, ty1 = tile.bounds
    assert (x0, y0) == (tx0, ty0)
    assert x1 == pytest.approx(tx1 + 2 * 25.0) and y1 == pytest.approx(ty1 + 20.0)


def test_scans_in_tile_zero_are_the_same_at_every_size(tile):
    big = tile_vector_map(tile, tiling_for_area(tile, 5000))
    laser = LaserSpec.from_degrees(10.0, 270.0, 0.25)
    rng = np.random.default_rng(1)
    x0, y0, x1, y1 = tile.bounds
    xy = rng.uniform((x0, y0), (x1, y1), size=(200, 2))
    xy = xy[tile.is_free(xy, 0.3)][:20]
    poses = np.column_stack((xy, rng.uniform(-np.pi, np.pi, len(xy))))
    assert len(poses) >= 10
    np.testing.assert_array_equal(big.raycast(poses, laser), tile.raycast(poses, laser))


def test_grid_under_tile_zero_is_the_same_at_every_size(tile):
    small = rasterize(tile, 0.1)
    big = rasterize(tile_vector_map(tile, tiling_for_area(tile, 1200)), 0.1)
    assert big.origin == small.origin
    x0, y0, x1, y1 = tile.bounds
    w = int((x1 - small.origin[0]) / 0.1)
    h = int((y1 - small.origin[1]) / 0.1)
    np.testing.assert_array_equal(big.occupancy[:h, :w], small.occupancy[:h, :w])
    assert big.occupancy.size > 3.5 * small.occupancy.size


def test_fit_loglog_on_synthetic_numbers():
    x = np.array([300.0, 1200.0, 5000.0, 20000.0])
    s = fit_loglog(x, 3.0 * x ** 0.5)
    assert s.slope == pytest.approx(0.5) and s.intercept == pytest.approx(math.log(3.0)) and s.n == 4
    assert s.grows
    flat = fit_loglog(x, np.full(4, 2.0))
    assert flat.slope == pytest.approx(0.0, abs=1e-12) and not flat.grows
    assert fit_loglog(x, x).slope == pytest.approx(1.0)
    # non-positive or NaN points are left out; one distinct x gives no slope
    assert fit_loglog(np.r_[x, 50.0], np.r_[x, np.nan]).n == 4
    assert math.isnan(fit_loglog(np.array([5.0, 5.0]), np.array([1.0, 2.0])).slope)


def test_slope_table_from_levels():
    rows = []
    for m, b in (("a", 0.0), ("b", 1.0)):
        for size in (100.0, 400.0, 1600.0):
            for k in range(3):
                rows.append({"axis": "area", "kind": "grid", "matcher": m, "level": f"{size:g}", "size": size,
                             "cpu_ms": 2.0 * size ** b * (1.0 + 0.01 * (k - 1)), "wall_ms": 1.0, "success": 1})
    levels = level_table(pd.DataFrame(rows))
    assert set(levels["n"]) == {3}
    sl = slope_table(levels).set_index("matcher")
    assert sl.loc["a", "slope"] == pytest.approx(0.0, abs=1e-9) and not sl.loc["a", "grows"]
    assert sl.loc["b", "slope"] == pytest.approx(1.0) and sl.loc["b", "grows"]
    assert sl.loc["a", "ms_per_unit"] == pytest.approx(0.0, abs=1e-9)
    assert sl.loc["b", "ms_per_unit"] == pytest.approx(2.0, rel=1e-3)


def test_study_end_to_end_on_a_tiny_configuration(tmp_path):
    study = _study()
    cfg = study.StudyConfig(areas_m2=(300.0, 1200.0), kinds=("vector", "grid"),
                            lasers=((180.0, 1.0), (180.0, 0.5)), resolution_m=0.1, scans_per_level=2,
                            scans_per_offset_bin=2, matchers=("tf-plus", "cv-corners"), warmup=1)
    result = study.run_study(cfg, log=lambda s: None)
    rows, prep = result["rows"], result["prep"]
    # every (axis, kind, level) × matcher × scan once
    area = rows[rows["axis"] == "area"]
    assert len(area) == 2 * 2 * 2 * 2 and len(rows[rows["axis"] == "beams"]) == 2 * 2 * 2
    assert len(rows[rows["axis"] == "offset"]) == 3 * 2 * 2
    # the same scans at every map size
    ids = area.groupby(["kind", "level"])["scan_id"].apply(lambda s: tuple(sorted(set(s))))
    assert ids.nunique() == 1
    assert sorted(rows.loc[rows["axis"] == "beams", "beams"].unique()) == [181, 361]
    assert (rows["cpu_ms"] > 0).all() and rows["success"].isin([0, 1]).all()
    assert (rows["sys_ms"] >= 0).all() and rows["sys_ms"].sum() <= rows["cpu_ms"].sum() * 1.05 + 20
    # preparation: the map itself and each matcher, for each area level and kind
    assert set(prep["matcher"]) == {"(map)", "tf-plus", "cv-corners"}
    assert len(prep) == 3 * 2 * 2 and (prep["status"] == "ok").all()
    grid = prep[(prep["kind"] == "grid") & (prep["matcher"] == "(map)")].sort_values("size")
    assert grid["cells"].iloc[1] > 3.5 * grid["cells"].iloc[0]
    study.write_results(tmp_path, result, cfg, {"cores": [1], "cpu": "test"})
    for f in ("scaling.csv", "prep.csv", "skips.csv", "levels.csv", "slopes.csv", "README.md", "scaling.png",
              "study.json"):
        assert (tmp_path / f).stat().st_size > 0, f
    readme = (tmp_path / "README.md").read_text()
    assert "**tf-plus**" in readme and "CPU per scan against map area, 5 cm grid" in readme
    # the tables and README are redrawn from the raw files alone, the same
    (tmp_path / "README.md").unlink()
    study.render(tmp_path)
    assert (tmp_path / "README.md").read_text() == readme


def test_a_matcher_over_budget_is_not_run_at_larger_levels():
    study = _study()
    cfg = study.StudyConfig(areas_m2=(300.0, 1200.0, 5000.0), kinds=("vector",), axes=("area",),
                            scans_per_level=2, matchers=("tf-plus",), budget_ms=1e-6)
    result = study.run_study(cfg, log=lambda s: None)
    assert set(result["rows"]["level"]) == {"1x1"}
    skips = result["skips"]
    assert list(skips["level"]) == ["2x2", "4x4"] and skips["why"].str.contains("> 1e-06 ms at 1x1").all()
    prep = result["prep"]
    assert list(prep.loc[prep["matcher"] == "tf-plus", "status"]) == ["ok", "skipped", "skipped"]


def test_tiling_needs_a_closed_tile():
    bare = VectorMap.from_segments(np.array([[0.0, 0.0, 5.0, 0.0]]))
    with pytest.raises(ConfigError, match="outline or a region"):
        tile_vector_map(bare, Tiling(2, 2, 6.0, 1.0))


def test_default_matchers_are_the_single_scan_local_ones():
    from tfloc.core.matcher import solves_global
    from tfloc.core.tracker import has_single_scan_mode

    study = _study()
    logged: list[str] = []
    chosen = study.build_matchers(None, logged.append)
    assert "tf-plus" in chosen and "tf" in chosen
    assert not any(solves_global(m) or not has_single_scan_mode(m) for m in chosen.values())
    left_out = " ".join(logged)
    assert "tf-global" in left_out and "a global matcher" in left_out
    assert "amcl" in left_out and "no single-scan mode" in left_out and "odometry" in left_out
    named = study.build_matchers(["tf-global"], logged.append)
    assert list(named) == ["tf-global"]  # named on the command line, it runs
    assert list(study.build_matchers(["odometry"], logged.append)) == ["odometry"]
