"""Sequence datasets (``"mode": "sequence"``): round trip, the one-line errors of a bad sequence
(stamps out of order, missing odometry, no starting pose), and the bundled sequences (simulated
and real) regenerated bit for bit."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from _committed import assert_same_file
from _paths import ROOT

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.datasets.sequences import BUNDLE, CONDITIONS, SequenceSpec, SimSpec, generate_sequences
from tfloc.errors import DatasetError
from tfloc.io.scenario import SEQUENCE, Scan, read_scans, read_scenario, write_scenario

MAP = ROOT / "data" / "maps" / "test-room.geojson"
LASER = LaserSpec.lms200()


def _write(root: Path, n: int = 4) -> Path:
    scans = [Scan(f"k{k}", "g", np.full(LASER.n_beams, 2.0), Pose(1.0, 2.0, 0.1) if k == 0 else None,
                  Pose(1.0 + 0.1 * k, 2.0, 0.1), stamp=10.0 + 0.1 * k, odom=Pose(0.1 * k, 0.0, 0.0))
             for k in range(n)]
    return write_scenario(root, "s", MAP, LASER, scans, mode=SEQUENCE)


def _edit(root: Path, line: int, column: str, value: str) -> None:
    p = root / "scans.csv"
    rows = p.read_text().splitlines()
    header = rows[0].split(",")
    cells = rows[line - 1].split(",")
    cells[header.index(column)] = value
    rows[line - 1] = ",".join(cells)
    p.write_text("\n".join(rows) + "\n")


def test_round_trip(tmp_path):
    sc = read_scenario(_write(tmp_path / "a"))
    assert sc.mode == SEQUENCE
    scans = read_scans(sc)
    assert [s.initial is None for s in scans] == [False, True, True, True]
    assert [s.stamp for s in scans] == pytest.approx([10.0, 10.1, 10.2, 10.3])
    assert scans[3].odom == Pose(0.3, 0.0, 0.0)


@pytest.mark.parametrize("line, column, value, message", [
    (3, "stamp", "9.0", r"scans.csv:3: stamp 9.0 is not after the previous row's"),
    (4, "stamp", "10.1", r"scans.csv:4: stamp 10.1 is not after"),
    (4, "stamp", "", r"scans.csv:4: a sequence needs a stamp on every row"),
    (3, "odom_x", "", r"scans.csv:3: odom pose is not|scans.csv:3: column 'odom_x' is not a number"),
    (2, "init_x", "", r"scans.csv:2: column 'init_x' is not a number|scans.csv:2: a sequence's first row needs"),
    (3, "odom_theta", "nan", r"scans.csv:3: odom pose is not finite"),
])
def test_bad_sequences_get_one_line_naming_file_and_line(tmp_path, line, column, value, message):
    root = _write(tmp_path / "b")
    _edit(root, line, column, value)
    with pytest.raises(DatasetError, match=message) as exc:
        read_scans(read_scenario(root))
    assert "\n" not in str(exc.value)


def test_missing_odometry_on_every_column_and_no_start(tmp_path):
    root = _write(tmp_path / "c")
    for c in ("odom_x", "odom_y", "odom_theta"):
        _edit(root, 3, c, "")
    with pytest.raises(DatasetError, match=r"scans.csv:3: a sequence needs odom_x/y/theta on every row"):
        read_scans(read_scenario(root))
    root = _write(tmp_path / "d")
    for c in ("init_x", "init_y", "init_theta"):
        _edit(root, 2, c, "")
    with pytest.raises(DatasetError, match=r"scans.csv:2: a sequence's first row needs init_x/y/theta"):
        read_scans(read_scenario(root))


def test_missing_columns(tmp_path):
    root = tmp_path / "e"
    scans = [Scan("k0", "g", np.full(LASER.n_beams, 2.0), Pose(1, 2, 0), stamp=1.0)]
    write_scenario(root, "e", MAP, LASER, scans, mode=SEQUENCE)
    with pytest.raises(DatasetError, match=r"scans.csv: a sequence needs the column\(s\) odom_x, odom_y, odom_theta"):
        read_scans(read_scenario(root))


def test_truth_may_be_empty(tmp_path):
    root = _write(tmp_path / "f")
    for c in ("true_x", "true_y", "true_theta"):
        _edit(root, 3, c, "")
    scans = read_scans(read_scenario(root))
    assert scans[1].true is None and scans[2].true is not None


def test_bundle_design():
    """≥ 5 sequences of ≥ 500 scans; every condition labelled; rate-1hz is up to 1 m and 30°."""
    for ds in BUNDLE:
        root = ROOT / "data" / "scenarios" / ds.name
        sc = read_scenario(root)
        assert sc.mode == SEQUENCE and sc.extra["condition"]["name"] == ds.condition
    long = [d for d in BUNDLE if json.loads((ROOT / "data/scenarios" / d.name / "scenario.json").read_text())
            ["generator"]["scans"] >= 500]
    assert len(long) >= 5
    g = json.loads((ROOT / "data/scenarios/seq-rate-1hz-b/scenario.json").read_text())["generator"]
    assert g["max_step_m"] == pytest.approx(1.0, abs=0.01) and g["max_turn_deg"] == pytest.approx(30.0, abs=0.1)
    assert set(CONDITIONS) == {"easy", "rate-2hz", "rate-1hz", "odom-high", "slip", "people", "combined"}


@pytest.mark.bitwise
def test_bundled_sequences_regenerate(tmp_path):
    """The bundled simulated sequences are what generate_sequences writes: the same bytes, or on
    another CPU within the last written digit (tests/_committed.py)."""
    (tmp_path / "maps").mkdir()
    for lv in (1, 2, 3):
        (tmp_path / "maps" / f"office-{lv}.geojson").write_bytes(
            (ROOT / "data" / "maps" / f"office-{lv}.geojson").read_bytes())
    generate_sequences(tmp_path, SimSpec())  # the whole bundle: ~10 s
    for ds in BUNDLE:
        for f in ("scans.csv", "scenario.json"):
            assert_same_file(tmp_path / "scenarios" / ds.name / f, ROOT / "data" / "scenarios" / ds.name / f)


def test_people_are_in_the_scans_not_in_the_map(tmp_path):
    (tmp_path / "maps").mkdir()
    (tmp_path / "maps" / "office-2.geojson").write_bytes((ROOT / "data/maps/office-2.geojson").read_bytes())
    spec = SimSpec(bundle=(SequenceSpec("p", "b", "people", 60), SequenceSpec("q", "b", "easy", 60)))
    generate_sequences(tmp_path, spec)
    from tfloc.io.maps import load_map

    m = load_map(tmp_path / "maps" / "office-2.geojson")
    short = []
    for name in ("p", "q"):
        scans = read_scans(read_scenario(tmp_path / "scenarios" / name))
        ideal = m.raycast(np.array([s.true.as_array() for s in scans]), LASER)
        got = np.array([s.ranges for s in scans])
        with np.errstate(invalid="ignore"):
            short.append(int(((ideal - got) > 0.1).sum()))
    assert short[0] > 50 and short[1] == 0
    assert not math.isnan(short[0])


@pytest.mark.bitwise
def test_real_sequences_regenerate(tmp_path):
    """`tfloc real-data`'s sequences: the committed files (tests/_committed.py); truth = the
    corrected poses in order."""
    from tfloc.datasets.real_sequences import build_sequences

    build_sequences(ROOT / "data" / "real", tmp_path)
    for key in ("intel", "csail", "aces"):
        rel = Path("scenarios") / f"real-{key}-sequence"
        assert_same_file(tmp_path / rel / "scans.csv", ROOT / "data" / rel / "scans.csv")
        a, b = (json.loads(p.read_text()) for p in (tmp_path / rel / "scenario.json",
                                                      ROOT / "data" / rel / "scenario.json"))
        a.pop("map"), b.pop("map")
        assert a == b
    scans = read_scans(read_scenario(ROOT / "data" / "scenarios" / "real-aces-sequence"))
    assert len(scans) == 440 and scans[0].initial == scans[0].true
