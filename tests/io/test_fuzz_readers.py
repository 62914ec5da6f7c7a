"""Every reader survives damaged input (hypothesis): the scenario directory, GeoJSON maps, ROS
map YAML + PGM, CARMEN logs, relations files and ``estimates.csv`` through ``tfloc report``.

Each test starts from a valid file, damages it (truncation, flipped and inserted bytes, NaN / inf /
1e308 / negative numbers, swapped or duplicated columns, blank, duplicated and huge lines; for
JSON and YAML also values replaced by arbitrary ones) and requires a valid result or a one-line
TflocError naming the file (see tests/_fuzz.py). ``make fuzz`` runs thousands of inputs per reader.
"""

from __future__ import annotations

import math
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from _estimates import row, write_run
from _fuzz import REPORT_SETTINGS, SETTINGS, Tally, damaged, finish, judge, mutated, write_files
from _paths import ROOT
from hypothesis import given

import tfloc
from tfloc.core.pose import Pose
from tfloc.io.carmen import read_carmen
from tfloc.io.geojson import read_vector_map
from tfloc.io.relations import join_relations, read_relations
from tfloc.io.rosmap import read_ros_map, write_ros_map
from tfloc.io.scenario import Scan, read_scans, read_scenario, write_scenario
from tfloc.maps.grid import GridMap

FIX = Path(__file__).parents[1] / "fixtures" / "real"
ROOM = ROOT / "data" / "maps" / "test-room.geojson"
LASER = tfloc.LaserSpec.from_degrees(8.0, 180.0, 2.0)  # 91 beams: small files, quick cases

pytestmark = pytest.mark.filterwarnings("ignore")


def _use(m) -> None:
    """What a harness does with a map it read: ask for its bounds and cast rays from inside it."""
    x0, y0, x1, y1 = m.bounds
    centre = np.array([[0.5 * (x0 + x1), 0.5 * (y0 + y1)]])
    if m.in_bounds(centre)[0]:
        m.raycast(Pose(float(centre[0, 0]), float(centre[0, 1]), 0.3), LASER)


@pytest.fixture(scope="module")
def scenario_files(tmp_path_factory) -> dict[str, bytes]:
    room = tfloc.load_map(ROOM)
    root = tmp_path_factory.mktemp("scenario") / "ds"
    scans = [Scan(f"s{i}", f"g{i % 2}", room.raycast(Pose(3 + 0.5 * i, 3.5, 0.2 * i), LASER),
                  Pose(3.1 + 0.5 * i, 3.4, 0.2 * i - 0.05), Pose(3 + 0.5 * i, 3.5, 0.2 * i) if i != 2 else None,
                  stamp=10.0 + i)
             for i in range(4)]
    write_scenario(root, "fuzz", ROOM, LASER, scans)
    return {"scenario.json": (root / "scenario.json").read_bytes(), "scans.csv": (root / "scans.csv").read_bytes()}


def test_scenario_directory(scenario_files) -> None:
    tally = Tally("scenario directory")
    with tempfile.TemporaryDirectory() as tmp:
        ds = Path(tmp) / "ds"
        ds.mkdir()

        @SETTINGS
        @given(damaged(scenario_files))
        def case(d):
            write_files(ds, d[1])
            judge(tally, d[0], lambda: read_scans(read_scenario(ds)), [str(ds)])

        case()
    finish(tally)


def test_geojson_map() -> None:
    tally = Tally("GeoJSON map")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "m.geojson"

        @SETTINGS
        @given(damaged({"m.geojson": ROOM.read_bytes()}))
        def case(d):
            write_files(path.parent, d[1])
            judge(tally, d[0][1:], lambda: _use(read_vector_map(path)), [str(path)])

        case()
    finish(tally)


@pytest.fixture(scope="module")
def ros_files(tmp_path_factory) -> dict[str, bytes]:
    occ = np.zeros((12, 16), dtype=np.float32)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = 1.0
    occ[5:7, 6:9] = 1.0
    occ[2, 3] = np.nan
    root = tmp_path_factory.mktemp("ros")
    write_ros_map(GridMap(occ, 0.25, (-1.0, -0.5), 0.65, 0.196, name="fuzz"), root / "map.yaml")
    return {"map.yaml": (root / "map.yaml").read_bytes(), "map.pgm": (root / "map.pgm").read_bytes()}


def test_ros_map(ros_files) -> None:
    tally = Tally("ROS map YAML+PGM")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)

        @SETTINGS
        @given(damaged(ros_files))
        def case(d):
            write_files(root, d[1])
            judge(tally, d[0], lambda: _use(read_ros_map(root / "map.yaml")), [str(root)])

        case()
    finish(tally)


@pytest.mark.parametrize("source", ["intel-head.log", "mit-csail-head.clf"])
def test_carmen_log(source: str) -> None:
    tally = Tally(f"CARMEN log ({source})")
    base = (FIX / source).read_bytes()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / source

        @SETTINGS
        @given(mutated(base))
        def case(m):
            what, blob = m
            path.write_bytes(blob)

            def read():
                log = read_carmen(path)
                log.poses()
                if len({len(r.ranges) for r in log.lasers}) == 1:
                    log.ranges()

            judge(tally, what, read, [str(path)], rf"^{path}(:\d+)?: ")

        case()
    finish(tally)


def test_relations_file() -> None:
    tally = Tally("relations file")
    scans = read_carmen(FIX / "mit-csail-head.clf").lasers
    t = [s.timestamp for s in scans]  # relations between the log's three scans, as the real file writes them
    base = "".join(f"{a:.5f} {b:.5f} 0.31293 0.02935 0.00000  0.00000 0.00000 0.24198\n"
                   for a, b in ((t[0], t[1]), (t[1], t[2]), (t[0], t[2]))).encode()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "x.relations"

        @SETTINGS
        @given(mutated(base))
        def case(m):
            what, blob = m
            path.write_bytes(blob)
            judge(tally, what, lambda: join_relations(read_relations(path), scans, path),
                  [str(path)], rf"^{path}(:\d+)?: ")

        case()
    finish(tally)


def _small_run(path: Path) -> None:
    """A run directory: a scan-to-map dataset and a scan-to-scan one, every status (small: the
    report's cost is per group, and the fuzz runs it hundreds of times)."""
    rows = []
    for d in ("detail-1", "real-x-relations"):
        for i in range(4):
            for m in ("tf", "csm-corr"):
                status = {1: "timeout", 2: "error:ValueError: x", 3: "invalid:ds/scans.csv:5: initial pose (9.000, "
                          "1.000) lies outside the map"}.get(i, "ok") if m == "tf" else "ok"
                ok = status == "ok"
                rows.append(row(m, 0.02 * (i + 1) if ok else None, 0.5 * i if ok else None, 0.4 + 0.9 * i,
                                3.0 * i, status, 0.01 if ok else None, d, f"{d}-{i}", "local" if i % 2 else "loop",
                                score_est=1.0 if i == 3 and ok else None, score_true=0.5 if i == 3 and ok else None))
    write_run(path, rows, {})


def _estimates_cases(tmp_path_factory, what: str, read, settings) -> None:
    """Damaged ``estimates.csv`` and ``run.json`` of a small run, each read by ``read(run_dir)``."""
    tally = Tally(what)
    src = tmp_path_factory.mktemp("run-src")
    _small_run(src)
    files = {n: (src / n).read_bytes() for n in ("estimates.csv", "run.json")}
    with tempfile.TemporaryDirectory() as tmp:
        run_dir = Path(tmp) / "run"

        @settings
        @given(damaged(files, {"estimates.csv": 2}))
        def case(d):
            shutil.rmtree(run_dir, ignore_errors=True)
            run_dir.mkdir()
            write_files(run_dir, d[1])
            judge(tally, d[0], lambda: read(run_dir), [str(run_dir)])

        case()
    finish(tally)


def test_estimates_through_the_reader(tmp_path_factory) -> None:
    """The results reader every command shares (rows and run.json: ``RunDir``)."""
    from tfloc.io.rundir import RunDir

    _estimates_cases(tmp_path_factory, "estimates.csv via RunDir", lambda d: (RunDir(d).results(), RunDir(d).info()),
                     SETTINGS)


def test_estimates_through_report(tmp_path_factory) -> None:
    """The same damage through the whole report (a few cases in make test, all in make fuzz: each
    case writes a report)."""
    from tfloc.cli.report import make_report as write_report

    _estimates_cases(tmp_path_factory, "estimates.csv via tfloc report",
                     lambda d: write_report(d, with_figures=False), REPORT_SETTINGS)


def test_the_oracle_bites(tmp_path) -> None:
    """A reader that raises a bare ValueError, or a TflocError not naming the file, is a defect."""
    tally = Tally("oracle")
    judge(tally, ["x"], lambda: float("x"), ["f"])
    judge(tally, ["y"], lambda: (_ for _ in ()).throw(tfloc.MapFormatError("something is wrong")), ["f.geojson"])
    judge(tally, ["z"], lambda: math.sqrt(4), ["f"])
    assert tally.tried == 3 and len(tally.defects) == 2 and tally.valid == 1
