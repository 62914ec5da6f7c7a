"""The scaling study (tfloc scaling): tiling, the same scans at every size, the slope fits, and the
verb end to end on a tiny configuration: its run directory (run.json, typed rows), the harness's
timer, resume, refusal of another configuration, --regenerate, and the README drawn from the
directory alone."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import shapely
from _paths import ROOT

from tfloc.cli import main
from tfloc.core.laser import LaserSpec
from tfloc.core.result import Status
from tfloc.core.rows.timing import PrepRow, ScanRow, SkipRow
from tfloc.datasets.tiling import Tiling, tile_vector_map, tiling_for_area
from tfloc.errors import ConfigError, ResultsError
from tfloc.evaluation.scaling import fit_loglog, level_table, slope_table
from tfloc.harness import workspace
from tfloc.harness.scaling import derive_scaling, scaling_study
from tfloc.harness.scaling_config import StudyConfig
from tfloc.harness.scaling_matchers import study_matchers
from tfloc.io.geojson import read_vector_map
from tfloc.io.rundir import RunDir
from tfloc.io.table import read_rows, write
from tfloc.io.tables import PREP, SCALING, SKIPS
from tfloc.maps.build import rasterize
from tfloc.maps.vector import VectorMap
from tfloc.report.scaling import render

FILES = {ScanRow: SCALING, PrepRow: PREP, SkipRow: SKIPS}


def render_scaling(run_dir: Path) -> pd.DataFrame:
    """What ``tfloc scaling`` does after the study: its tables derived, then drawn; the slopes."""
    rows, prep, skips, levels, slopes = derive_scaling(run_dir)
    render(run_dir, rows, prep, skips, levels, slopes, RunDir(run_dir).info())
    return slopes

OFFICE = ROOT / "data" / "maps" / "office-1.geojson"
#: The tiny study: 2 areas × 2 kinds, the 4 lasers, the 3 offset bins; 2 scans each; 2 cheap matchers.
TINY = ["--matchers", "tf-plus,cv-corners", "--areas", "300,1200", "--scans", "2", "--scans-per-bin", "2",
        "--map", str(OFFICE), "--no-progress"]


def raw(out: Path) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """The study's tables of scan, preparation and skip rows, read as typed rows."""
    return tuple(RunDir(out).frame(FILES[c]) for c in (ScanRow, PrepRow, SkipRow))


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


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """``tfloc scaling`` on the tiny configuration, with every call of the harness's timer
    recorded: (the called function's name, its :class:`~tfloc.harness.workspace.Timed`)."""
    out = tmp_path_factory.mktemp("scaling") / "study"
    calls: list[tuple[str, workspace.Timed]] = []
    real = workspace.timed

    def spy(call, *args, **kwargs):
        t = real(call, *args, **kwargs)
        calls.append((getattr(call, "__name__", ""), t))
        return t

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(workspace, "timed", spy)
        assert main(["scaling", "--out", str(out), *TINY]) == 0
    return out, calls


def test_the_verb_end_to_end_on_a_tiny_configuration(study, tmp_path):
    out, _ = study
    for f in ("scaling.csv", "prep.csv", "skips.csv", "levels.csv", "slopes.csv", "README.md", "scaling.png",
              "run.json"):
        assert (out / f).stat().st_size > 0, f
    assert not (out / "study.json").exists()
    rows, prep, skips = raw(out)
    # every (axis, kind, level) × matcher × scan once
    area = rows[rows["axis"] == "area"]
    assert len(area) == 2 * 2 * 2 * 2 and len(rows[rows["axis"] == "beams"]) == 4 * 2 * 2
    assert len(rows[rows["axis"] == "offset"]) == 3 * 2 * 2
    assert not rows.duplicated(["axis", "kind", "level", "matcher", "scan_id"]).any()
    # the same scans at every map size
    ids = area.groupby(["kind", "level"])["scan_id"].apply(lambda s: tuple(sorted(set(s))))
    assert ids.nunique() == 1
    assert sorted(rows.loc[rows["axis"] == "beams", "beams"].unique()) == [181, 361, 721, 1081]
    assert rows["status"].isin(["ok", "failed"]).all() and (rows["cpu_ms"] > 0).all()
    assert rows["success"].isin([0, 1]).all() and not rows.loc[rows["status"] == "failed", "success"].any()
    assert (rows["sys_ms"] >= 0).all() and rows["sys_ms"].sum() <= rows["cpu_ms"].sum() * 1.05 + 20
    # interleaved: each matcher first on every other scan
    first = rows[rows["position"] == 0].groupby(["axis", "kind", "level"])["matcher"].nunique()
    assert (first == 2).all()
    # preparation: the map itself and each matcher, for each area level and kind
    assert set(prep["matcher"]) == {"(map)", "tf-plus", "cv-corners"}
    assert len(prep) == 3 * 2 * 2 and (prep["status"] == "ok").all() and skips.empty
    grid = prep[(prep["kind"] == "grid") & (prep["matcher"] == "(map)")].sort_values("size")
    assert grid["cells"].iloc[1] > 3.5 * grid["cells"].iloc[0]
    readme = (out / "README.md").read_text()
    assert "Written by `tfloc scaling`" in readme and "issue" not in readme
    assert "**tf-plus**" in readme and "CPU per scan against map area, 5 cm grid" in readme
    assert "`run.json`: the configuration" in readme
    # typed rows: statuses are Status, and the files are the rows written again, byte for byte
    for cls in (ScanRow, PrepRow, SkipRow):
        name = FILES[cls].name
        typed = read_rows(out / name, FILES[cls])
        assert cls is SkipRow or all(isinstance(r.status, Status) for r in typed)
        write(tmp_path / name, FILES[cls], typed)
        assert (tmp_path / name).read_text() == (out / name).read_text()
    # run.json: a run directory's record of the code and configuration that made it
    info = RunDir(out).info(required=True)
    assert info.kind == "scaling" and info.labels == ["tf-plus", "cv-corners"]
    assert info.study["scans_per_level"] == 2 and info.study["matchers"] == ["tf-plus", "cv-corners"]
    assert info.paths == {"office-1": OFFICE} and info.thresholds.dist_m == 0.1
    assert set(info.fingerprint["matchers"]) == {"tf-plus", "cv-corners"}
    assert info.fingerprint["scaling"] == info.study
    assert info.git.commit is not None and info.git.dirty is not None and info.versions["numpy"]
    assert info.machine.python and info.machine.cpu
    assert info.done == info.levels and len(info.levels) == 4 + 4 + 3
    (session,) = info.sessions
    assert session.started <= session.ended and len(session.cores) == 1 and session.cpu_s > 0
    assert session.loadavg_start and session.loadavg_end and session.tasks == 11 * 2 * 2
    assert info.command.startswith("tfloc scaling --out ")
    assert StudyConfig.from_dict(dict(info.study)) == StudyConfig(
        map_path=str(OFFICE), areas_m2=(300.0, 1200.0), scans_per_level=2, scans_per_offset_bin=2,
        matchers=("tf-plus", "cv-corners"))


def test_the_study_times_with_the_harness_timer(study):
    out, calls = study
    rows, _, _ = raw(out)
    timed = [1000.0 * t.cpu_s for name, t in calls if name == "localize"]
    assert len(timed) == len(rows)
    np.testing.assert_allclose(rows["cpu_ms"], timed, rtol=1e-5)


def test_the_readme_is_drawn_from_the_run_directory_alone(study, tmp_path):
    out, _ = study
    copy = tmp_path / "copy"
    copy.mkdir()
    for f in ("run.json", "scaling.csv", "prep.csv", "skips.csv"):
        shutil.copy(out / f, copy / f)
    slopes = render_scaling(copy)
    assert (copy / "README.md").read_text() == (out / "README.md").read_text()
    assert (copy / "slopes.csv").read_text() == (out / "slopes.csv").read_text() and len(slopes)
    (copy / "run.json").unlink()
    with pytest.raises(ResultsError, match="no scaling study here"):
        render_scaling(copy)


def test_a_complete_study_is_only_redrawn(study, capsys):
    out, _ = study
    before = {f: (out / f).read_text() for f in ("scaling.csv", "prep.csv", "README.md", "run.json")}
    assert main(["scaling", "--out", str(out), *TINY]) == 0
    assert {f: (out / f).read_text() for f in before} == before
    err = capsys.readouterr().err
    assert f"{out}: already complete: 0 levels run (--regenerate runs it again)" in err and "slope" in err


def test_a_directory_of_another_configuration_is_refused(study, capsys):
    out, _ = study
    before = {f: (out / f).read_text() for f in ("scaling.csv", "run.json")}
    assert main(["scaling", "--out", str(out), *TINY[:5], "3", *TINY[6:]]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"tfloc scaling: error: {out} holds a study of another configuration: scans_per_level 2 → 3; "
                   "to start it over give --regenerate, to keep it choose another --out")
    assert {f: (out / f).read_text() for f in before} == before


def test_an_interrupted_study_resumes_without_mixing_rows(study, tmp_path, capsys):
    src, _ = study
    out = tmp_path / "cut"
    shutil.copytree(src, out)
    doc = json.loads((out / "run.json").read_text())
    doc["done"] = doc["done"][:-2]   # killed after the rows of the last two levels, before run.json
    (out / "run.json").write_text(json.dumps(doc))
    assert main(["scaling", "--out", str(out), *TINY]) == 0
    assert f"{out}: resuming: 9 of 11 levels done by the same code and configuration" in capsys.readouterr().err
    rows, prep, _ = raw(out)
    old, _, _ = raw(src)
    assert len(rows) == len(old) and not rows.duplicated(["axis", "kind", "level", "matcher", "scan_id"]).any()
    assert len(prep) == 3 * 2 * 2
    doc = json.loads((out / "run.json").read_text())
    assert doc["done"] == doc["levels"] and [s["levels_done_before"] for s in doc["sessions"]] == [0, 9]
    assert [s["already_done"] for s in doc["sessions"]] == [0, 9 * 2 * 2]


def test_regenerate_starts_another_configuration_or_an_old_directory_over(tmp_path):
    small = StudyConfig(map_path=str(OFFICE), axes=("offset",), scans_per_offset_bin=1, matchers=("cv-corners",))
    out = tmp_path / "study"
    out.mkdir()
    (out / "study.json").write_text("{}")           # a study made by an older tfloc
    (out / "scaling.csv").write_text("matcher\n")
    with pytest.raises(ConfigError, match="it records no fingerprint .*--regenerate"):
        scaling_study(small, out, log=lambda s: None)
    scaling_study(small, out, regenerate=True, log=lambda s: None)
    assert not (out / "study.json").exists() and len(raw(out)[0]) == 3
    bigger = StudyConfig.from_dict({"scans_per_offset_bin": 2}, base=small)
    with pytest.raises(ConfigError, match="scans_per_offset_bin 1 → 2"):
        scaling_study(bigger, out, log=lambda s: None)
    scaling_study(bigger, out, regenerate=True, log=lambda s: None)
    info = RunDir(out).info()
    assert len(raw(out)[0]) == 6 and info.study["scans_per_offset_bin"] == 2 and len(info.sessions) == 1
    logged: list[str] = []
    scaling_study(bigger, out, regenerate=True, log=logged.append)   # complete: runs again
    assert not any("already complete" in s for s in logged) and len(RunDir(out).info().sessions) == 1


def test_a_matcher_over_budget_is_not_run_at_larger_levels(tmp_path):
    cfg = StudyConfig(map_path=str(OFFICE), areas_m2=(300.0, 1200.0, 5000.0), kinds=("vector",), axes=("area",),
                      scans_per_level=2, matchers=("tf-plus",), budget_ms=1e-6)
    rows, prep, skips = raw(scaling_study(cfg, tmp_path, log=lambda s: None).path)
    assert set(rows["level"]) == {"1x1"}
    assert list(skips["level"]) == ["2x2", "4x4"] and skips["why"].str.contains("> 1e-06 ms at 1x1").all()
    assert list(prep.loc[prep["matcher"] == "tf-plus", "status"]) == ["ok", "skipped", "skipped"]
    assert [r.status for r in read_rows(tmp_path / "prep.csv", PREP) if r.matcher == "tf-plus"][1:] == [None, None]


def test_tiling_needs_a_closed_tile():
    bare = VectorMap.from_segments(np.array([[0.0, 0.0, 5.0, 0.0]]))
    with pytest.raises(ConfigError, match="outline or a region"):
        tile_vector_map(bare, Tiling(2, 2, 6.0, 1.0))


def test_default_matchers_are_the_single_scan_local_ones():
    from tfloc.core.matcher import solves_global
    from tfloc.core.tracker import has_single_scan_mode

    logged: list[str] = []
    chosen = study_matchers(None, logged.append)
    assert "tf-plus" in chosen and "tf" in chosen
    assert not any(solves_global(m) or not has_single_scan_mode(m) for m in chosen.values())
    left_out = " ".join(logged)
    assert "tf-global" in left_out and "a global matcher" in left_out
    assert "amcl" in left_out and "no single-scan mode" in left_out and "odometry" in left_out
    assert list(study_matchers(["tf-global"], logged.append)) == ["tf-global"]  # named, it runs
    assert list(study_matchers(["odometry"], logged.append)) == ["odometry"]
    logged.clear()
    assert list(study_matchers(["tf-plus", "amcl"], logged.append)) == ["tf-plus"]  # a tracker never does
    assert logged == ["left out: amcl (no single-scan mode)"]
    with pytest.raises(ConfigError, match="registered matchers only"):
        study_matchers(["toy_matchers:Stay"], logged.append)


def test_bad_study_configurations_are_refused():
    with pytest.raises(ConfigError, match="axis 'size'"):
        StudyConfig(axes=("size",))
    with pytest.raises(ConfigError, match="scans per level 0"):
        StudyConfig(scans_per_level=0)
    assert StudyConfig.quick().scans_per_level == 9 and StudyConfig().scans_per_level == 45
    # a study file's [scaling] table
    cfg = StudyConfig.from_dict({"lasers": [[180, 1]], "areas_m2": [300, 1200], "matchers": ["tf-plus"],
                                 "budget_ms": 100})
    assert cfg.lasers == ((180.0, 1.0),) and cfg.areas_m2 == (300.0, 1200.0) and cfg.matchers == ("tf-plus",)
    assert cfg.budget_ms == 100.0 and cfg.scans_per_level == 45
    assert StudyConfig.from_dict({"budget_ms": 1.0}, base=StudyConfig.quick()).scans_per_level == 9
    with pytest.raises(ConfigError, match="unknown field.*'scans'"):
        StudyConfig.from_dict({"scans": 3})
    for bad in ({"scans_per_level": 2.5}, {"matchers": "tf-plus"}, {"matchers": [1]}, {"warmup": True}):
        with pytest.raises(ConfigError, match=f"field '{next(iter(bad))}'"):
            StudyConfig.from_dict(bad)
