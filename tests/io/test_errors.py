"""Bad input gets one clear error naming the file, row or field — never a numpy traceback."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _paths import ROOT

import tfloc
from tfloc import InvalidProblemError, MapFormatError, Pose, Problem
from tfloc.errors import DatasetError
from tfloc.io.scenario import Scan, read_scans, read_scenario, write_scenario

ROOM = ROOT / "data" / "maps" / "test-room.geojson"


@pytest.mark.parametrize("text, needle", [
    ("{not json", "not valid JSON"),
    ('{"type": "Feature"}', "FeatureCollection"),
    ('{"type": "FeatureCollection", "features": []}', "non-empty"),
    ('{"type": "FeatureCollection", "features": [{"type": "Feature"}]}', "feature 0"),
    ('{"type": "FeatureCollection", "features": [{"type": "Feature", "geometry": '
     '{"type": "LineString", "coordinates": [[0, 0], ["a", 1]]}}]}', "feature 0"),
    ('{"type": "FeatureCollection", "features": [{"type": "Feature", "geometry": '
     '{"type": "Point", "coordinates": [0, 0]}}]}', "unsupported geometry type Point"),
])
def test_malformed_geojson(tmp_path, text, needle):
    p = tmp_path / "bad.geojson"
    p.write_text(text)
    with pytest.raises(MapFormatError, match=needle) as exc:
        tfloc.load_map(p)
    assert str(p) in str(exc.value) and "\n" not in str(exc.value)


def test_missing_and_unknown_map_files(tmp_path):
    with pytest.raises(MapFormatError, match="no such map file"):
        tfloc.load_map(tmp_path / "nope.geojson")
    with pytest.raises(MapFormatError, match="unknown map type"):
        tfloc.load_map(tmp_path / "map.png")


@pytest.fixture
def dataset(tmp_path, test_room, lms200):
    scans = [Scan(f"s{i}", "g", test_room.raycast(Pose(3, 3.5, 0.1 * i), lms200),
                  Pose(3.1, 3.4, 0.1 * i), None) for i in range(3)]
    return write_scenario(tmp_path / "ds", "tiny", ROOM, lms200, scans)


def corrupt(ds: Path, line: int, fn) -> None:
    p = ds / "scans.csv"
    lines = p.read_text().splitlines()
    lines[line - 1] = fn(lines[line - 1])
    p.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("fn, needle", [
    (lambda s: s.rsplit(" ", 1)[0], "180 ranges, expected 181"),
    (lambda s: s.rsplit(",", 1)[0] + ",abc " + s.rsplit(",", 1)[1].split(" ", 1)[1],
     "range 'abc' is not a number"),
    (lambda s: s.replace(" ", " -1.5 ", 1).rsplit(" ", 1)[0], "negative range -1.5"),
    (lambda s: ",".join(s.split(",")[:8]) + "," + " ".join(["inf"] * 181), "no return at all"),
    (lambda s: s.replace(",g,", ",g,", 1).replace(",3.1", ",x", 1), "init_x"),
    (lambda s: s.split(",", 1)[0], "wrong number of fields"),
])
def test_malformed_scan_rows_name_file_and_line(dataset, fn, needle):
    corrupt(dataset, 3, fn)
    with pytest.raises(DatasetError, match=needle) as exc:
        read_scans(read_scenario(dataset))
    assert "scans.csv:3:" in str(exc.value)


def test_empty_truth_is_fine(dataset):
    scans = read_scans(read_scenario(dataset))
    assert len(scans) == 3 and all(s.true is None for s in scans)


def test_bad_scenario_json(tmp_path):
    (tmp_path / "scenario.json").write_text(json.dumps({"name": "x", "map": "m.geojson", "laser": {}}))
    with pytest.raises(DatasetError, match="bad 'laser' field"):
        read_scenario(tmp_path)
    with pytest.raises(DatasetError, match="nothing: no such directory"):
        read_scenario(tmp_path / "nothing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(DatasetError, match="not a scenario dataset"):
        read_scenario(tmp_path / "empty")


def test_problem_validation(test_room, lms200):
    good = test_room.raycast(Pose(3, 3.5, 0), lms200)
    with pytest.raises(InvalidProblemError, match="180 ranges"):
        Problem(test_room, lms200, good[:-1], Pose(3, 3.5, 0))
    with pytest.raises(InvalidProblemError, match="negative range"):
        Problem(test_room, lms200, np.where(np.arange(181) == 5, -1.0, good), Pose(3, 3.5, 0))
    with pytest.raises(InvalidProblemError, match="no return at all"):
        Problem(test_room, lms200, np.full(181, np.nan), Pose(3, 3.5, 0))
    with pytest.raises(InvalidProblemError, match="outside the map"):
        Problem(test_room, lms200, good, Pose(30, 3.5, 0))
    with pytest.raises(InvalidProblemError, match="not numeric"):
        Problem(test_room, lms200, ["a"] * 181, Pose(3, 3.5, 0))
    # NaN/inf are no-returns, allowed while some beam returns
    Problem(test_room, lms200, np.where(np.arange(181) < 20, np.inf, good), Pose(3, 3.5, 0))


def _numpy_range_verdict(r: np.ndarray, laser) -> str:
    """The range rule in numpy steps (the compiled pass's oracle): the message, or "" if valid."""
    with np.errstate(invalid="ignore"):
        neg = np.flatnonzero(r < 0)
    if neg.size:
        return f"negative range {r[neg[0]]:g} at beam {neg[0]}"
    return "" if laser.valid(r).any() else "no return at all"


def test_the_compiled_range_check_gives_the_numpy_rule_s_verdicts(lms200):
    from tfloc.core.problem import check_ranges

    rng = np.random.default_rng(11)
    specials = np.array([np.nan, np.inf, -np.inf, 0.0, -0.0, -1e-300, lms200.max_range,
                         np.nextafter(lms200.max_range, 0.0), 1e-300, -2.5])
    verdicts = set()
    for k in range(400):
        r = rng.uniform(0.0, 12.0, 362)
        r[rng.random(362) < rng.uniform(0.0, 1.0)] = rng.choice(specials)
        if k % 4 == 0:
            r[:] = rng.choice(specials[[0, 1, 3, 4, 6]])    # every beam without a return
        r = r[::2]                                          # a strided view, 181 beams
        want = _numpy_range_verdict(r, lms200)
        verdicts.add(want.split(" ")[0])
        if want:
            with pytest.raises(InvalidProblemError) as err:
                check_ranges(r, lms200)
            assert want in str(err.value)
        else:
            assert check_ranges(r, lms200).tobytes() == r.tobytes()
    assert verdicts == {"", "negative", "no"}


def test_unknown_matcher():
    with pytest.raises(tfloc.MatcherError, match="unknown matcher 'nope'"):
        tfloc.get_matcher("nope")


def cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "tfloc.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=300)


def test_cli_localize_writes_rows_without_truth(dataset, tmp_path):
    out = tmp_path / "est.csv"
    r = cli("localize", "--dataset", dataset, "--matcher", "tf", "--out", out, "--limit", "2")
    assert r.returncode == 0, r.stderr
    import pandas as pd

    df = pd.read_csv(out)
    assert list(df.scan_id) == ["s0", "s1"]
    for col in ("scan_id", "matcher", "est_x", "est_y", "est_theta", "runtime_s", "cpu_s", "converged",
                "iterations", "status"):
        assert col in df.columns
    assert df.runtime_s.gt(0).all() and df.cpu_s.gt(0).all() and df.matcher.eq("tf").all()


def test_cli_bad_input_is_one_line_without_traceback(dataset, tmp_path):
    corrupt(dataset, 2, lambda s: s.rsplit(" ", 1)[0])
    r = cli("localize", "--dataset", dataset, "--out", tmp_path / "e.csv")
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert "scans.csv:2:" in r.stderr
    bad_map = tmp_path / "bad.geojson"
    bad_map.write_text("{")
    r = cli("localize", "--dataset", dataset, "--map", bad_map, "--out", tmp_path / "e.csv")
    assert r.returncode == 2 and "bad.geojson" in r.stderr and "Traceback" not in r.stderr


def test_cli_pose_outside_map_is_an_invalid_row_naming_the_row(dataset, tmp_path):
    """The data poses no problem for that scan: its row says why (status invalid:…), the others run."""
    corrupt(dataset, 3, lambda s: s.replace(",3.100000,", ",99.000000,", 1))
    r = cli("localize", "--dataset", dataset, "--out", tmp_path / "e.csv")
    assert r.returncode == 0 and "invalid 1" in r.stderr, r.stderr
    df = pd.read_csv(tmp_path / "e.csv")
    assert df.status.iloc[1].startswith("invalid:") and "scans.csv:3" in df.status.iloc[1]
    assert "outside the map" in df.status.iloc[1] and df.status.iloc[0] == "ok" and df.est_x.iloc[1] != df.est_x.iloc[1]
