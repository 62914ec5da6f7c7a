"""The native-rate real sequences (``real-<log>-native``, tfloc.datasets.real_native): the committed
datasets regenerated bit for bit, their counts, matching and stamps against the logs, the raw scan
reader's and the matcher's one-line errors, and relation errors of a tracked trajectory."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from _committed import assert_same_file
from _paths import REAL, SCEN

from tfloc.core.pose import Pose
from tfloc.datasets.real import clean_ranges, front_scans
from tfloc.datasets.real_native import (
    CORRECTED,
    NATIVE_LOGS,
    build_native,
    interpolated_stamps,
    match_corrected,
    native_scans,
)
from tfloc.errors import DatasetError, LogFormatError
from tfloc.evaluation.relations import tracked_relation_errors, tracked_relation_stats
from tfloc.io.carmen import read_carmen, read_flaser_no_timestamps
from tfloc.io.relations import Relation, read_relations, relations_path
from tfloc.io.scenario import read_scans, read_scenario

#: (key, scans in the dataset, truth-bearing scans, raw scans in the log)
COUNTS = (("intel", 13462, 910, 13631), ("csail", 1927, 406, 1988), ("aces", 7238, 440, 7374))


@pytest.fixture(scope="module")
def rebuilt(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("native")
    build_native(REAL, out)
    return out


@pytest.fixture(scope="module")
def datasets() -> dict:
    return {key: (sc := read_scenario(SCEN / f"real-{key}-native"), read_scans(sc)) for key, *_ in COUNTS}


@pytest.mark.bitwise
@pytest.mark.parametrize("key", [c[0] for c in COUNTS])
def test_committed_native_datasets_regenerate(rebuilt: Path, key: str) -> None:
    """`tfloc real-data` writes the committed files (tests/_committed.py); paths are relative to
    where they were written, so they are left out of the scenario.json comparison."""
    rel = Path("scenarios") / f"real-{key}-native"
    assert_same_file(rebuilt / rel / "scans.csv", SCEN.parent / rel / "scans.csv")
    a, b = (json.loads((d / rel / "scenario.json").read_text()) for d in (rebuilt, SCEN.parent))
    for doc in (a, b):
        doc.pop("map"), doc.pop("relations", None)
    assert a == b


@pytest.mark.parametrize(("key", "n", "n_truth", "n_raw"), COUNTS)
def test_counts_matching_and_start(datasets, key: str, n: int, n_truth: int, n_raw: int) -> None:
    """Every raw scan from the first corrected one on; truth exactly on the corrected scans, in
    order, with their ranges; the start is the first corrected pose; odometry on every row."""
    sc, scans = datasets[key]
    assert sc.mode == "sequence" and sc.extra["condition"]["name"] == "real-native"
    assert len(scans) == n and scans[-1].scan_id == f"r{n_raw - 1:05d}"
    rel, laser, no_return = CORRECTED[key]
    corr = front_scans(read_carmen(REAL / rel), laser)
    truth = [s for s in scans if s.true is not None]
    assert len(truth) == len(corr) == n_truth
    assert scans[0].true is not None and scans[0].initial == scans[0].true
    assert all(s.initial is None for s in scans[1:]) and all(s.odom is not None for s in scans)
    for s, c in zip(truth, corr, strict=True):
        assert s.true.distance_to(c.pose) < 1e-6 and abs(s.true.theta - c.pose.theta) < 1e-6
        np.testing.assert_array_equal(s.ranges, clean_ranges(c.ranges, no_return))


@pytest.mark.parametrize("key", ["intel", "aces"])
def test_raw_odometry_is_the_files(datasets, key: str) -> None:
    """odom_* is the raw scan file's odometry, as logged (to the written µm / 0.1 µrad)."""
    _, scans = datasets[key]
    log = next(g for g in NATIVE_LOGS if g.key == key)
    raw = read_flaser_no_timestamps(REAL / log.raw)
    first = int(scans[0].scan_id[1:])
    odom = np.array([s.odom.as_array() for s in scans])
    np.testing.assert_allclose(odom, raw.odom[first:], atol=1e-6, rtol=0)


def test_csail_stamps_and_odometry_are_the_clf_own(datasets) -> None:
    _, scans = datasets["csail"]
    clf = read_carmen(REAL / "mit-csail" / "mit-csail.clf.gz").lasers[61:]
    np.testing.assert_allclose([s.stamp for s in scans], [c.timestamp for c in clf], atol=1e-6, rtol=0)
    np.testing.assert_allclose([s.odom.as_array() for s in scans], [c.odom.as_array() for c in clf],
                               atol=1e-6, rtol=0)


@pytest.mark.parametrize(("key", "dropped"), [("intel", 4), ("aces", 0)])
def test_interpolated_stamps_meet_the_corrected_times(datasets, key: str, dropped: int) -> None:
    """At the corrected scans the stamps are the corrected log's logger times, but for the few
    times that are not below a later one (left out of the interpolation)."""
    sc, scans = datasets[key]
    rel, laser, _ = CORRECTED[key]
    times = np.array([c.logger_timestamp for c in front_scans(read_carmen(REAL / rel), laser)])
    got = np.array([s.stamp for s in scans if s.true is not None])
    off = np.abs(got - times) > 1e-6
    assert off.sum() == dropped == sc.extra["generator"]["knots_dropped"]
    assert np.all(np.diff([s.stamp for s in scans]) > 0)


def test_interpolation_by_hand() -> None:
    """Knots (2, 1.0) (4, 2.0) (6, 1.9) (8, 3.0): (4, 2.0) is not below a later time and is left
    out; the median period of the kept gaps (0.225, 0.55 s per scan) = 0.3875 s extends the ends."""
    st = interpolated_stamps(np.array([2, 4, 6, 8]), np.array([1.0, 2.0, 1.9, 3.0]), 10, "x")
    assert st.dropped == 1 and st.period_s == pytest.approx(0.3875)
    want = [1.0 - 2 * 0.3875, 1.0 - 0.3875, 1.0, 1.225, 1.45, 1.675, 1.9, 2.45, 3.0, 3.3875]
    np.testing.assert_allclose(st.seconds, want, atol=1e-12)
    with pytest.raises(DatasetError, match=r"^x: fewer than two increasing"):
        interpolated_stamps(np.array([1, 2]), np.array([5.0, 4.0]), 3, "x")


# --- bad input -----------------------------------------------------------------------------

def _raw_file(path: Path, ranges: np.ndarray, header: str = "# raw\n") -> Path:
    lines = [f"{k} {len(r)} " + " ".join(f"{v:.2f}" for v in r) + f" {0.1 * k:.3f} 0.0 0.0"
             for k, r in enumerate(ranges)]
    path.write_text(header + "\n".join(lines) + "\n")
    return path


def _corrected_log(path: Path, ranges: np.ndarray, times: list[float]) -> Path:
    lines = [f"FLASER {len(r)} " + " ".join(f"{v:.2f}" for v in r) + f" {0.1 * k:.3f} 0 0 {0.1 * k:.3f} 0 0 {t} pippo {t}"
             for k, (r, t) in enumerate(zip(ranges, times, strict=True))]
    path.write_text("\n".join(lines) + "\n")
    return path


def _tiny(tmp_path: Path, raw_order: list[int] | None = None) -> tuple[Path, np.ndarray]:
    """An Intel-shaped pair of files: 10 raw scans, of which 2, 5, 8 are the corrected log's."""
    rng = np.random.default_rng(1)
    R = np.round(rng.uniform(0.5, 9.0, (10, 180)), 2)
    (tmp_path / "intel").mkdir(exist_ok=True)
    _raw_file(tmp_path / "intel" / "intel.flaser_no_timestamps.txt.gz", R if raw_order is None else R[raw_order])
    _corrected_log(tmp_path / "intel" / "intel-corrected.log.gz", R[[2, 5, 8]], [10.0, 10.6, 11.2])
    return tmp_path, R


def test_a_tiny_log_end_to_end(tmp_path) -> None:
    real, _ = _tiny(tmp_path)
    rows, summary = native_scans(real, NATIVE_LOGS[0])
    assert [r.scan_id for r in rows] == [f"r{k:05d}" for k in range(2, 10)]
    assert [r.true is not None for r in rows] == [True, False, False, True, False, False, True, False]
    np.testing.assert_allclose([r.stamp for r in rows], [10.0 + 0.2 * k for k in range(8)], atol=1e-9)
    assert rows[0].initial == rows[0].true and rows[1].odom == Pose(0.3, 0.0, 0.0)
    assert summary["truth_scans"] == 3 and summary["knots_dropped"] == 0


@pytest.mark.parametrize(("order", "message"), [
    ([0, 1, 3, 4, 5, 6, 7, 8, 9], r"intel-corrected.log.gz:1: the corrected scan's ranges equal 0 scans of"),
    ([0, 1, 2, 2, 4, 5, 6, 7, 8, 9], r"intel-corrected.log.gz:1: the corrected scan's ranges equal 2 scans of "
                                     r".*\(2, 3\) where exactly one is expected"),
    ([0, 1, 5, 3, 4, 2, 6, 7, 8, 9], r"intel-corrected.log.gz:2: the corrected scan equals raw scan 2 of .*"
                                     r"not after raw scan 5 .*not in order"),
])
def test_a_bad_match_is_one_line_naming_the_file(tmp_path, order, message) -> None:
    real, _ = _tiny(tmp_path, order)
    with pytest.raises(DatasetError, match=message) as exc:
        native_scans(real, NATIVE_LOGS[0])
    assert "\n" not in str(exc.value)


def test_match_corrected_alone() -> None:
    raw = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])
    np.testing.assert_array_equal(match_corrected(raw, raw[[0, 2]], Path("r"), Path("c"), np.array([7, 9])),
                                  [0, 2])
    with pytest.raises(DatasetError, match=r"^c:9: .*equal 0 scans of r"):
        match_corrected(raw, np.array([[1.0, 2.0], [5.0, 6.5]]), Path("r"), Path("c"), np.array([7, 9]))


GOOD = "0 3 1.00 2.00 3.00 0.1 0.2 0.3\n1 3 1.50 2.50 3.50 0.2 0.2 0.3\n"


@pytest.mark.parametrize(("text", "message"), [
    ("# only a comment\n", r"raw.txt: no scans in the file"),
    (GOOD + "3 3 1 2 3 0 0 0\n", r"raw.txt:3: scan index 3, expected 2"),
    (GOOD + "2 4 1 2 3 4 0 0 0\n", r"raw.txt:3: 4 beams, expected 3"),
    (GOOD + "2 3 1 2 3 0 0\n", r"raw.txt:3: 7 fields, expected 8"),
    (GOOD + "2 3 1 x 3 0 0 0\n", r"raw.txt:3: field 4 is not a number: 'x'"),
    (GOOD + "2 3 1 2 3 nan 0 0\n", r"raw.txt:3: field 6 is not finite"),
    (GOOD + "2 3 1 -2 3 0 0 0\n", r"raw.txt:3: negative range at beam 1"),
    (GOOD + "two 3 1 2 3 0 0 0\n", r"raw.txt:3: expected '<scan_index> <n_beams>"),
    ("0 0 0 0 0\n", r"raw.txt:1: 0 beams"),
])
def test_bad_raw_scan_files_get_one_line_naming_file_and_line(tmp_path, text, message) -> None:
    p = tmp_path / "raw.txt"
    p.write_text(text)
    with pytest.raises(LogFormatError, match=message) as exc:
        read_flaser_no_timestamps(p)
    assert "\n" not in str(exc.value)


def test_raw_scan_file_reads_gzip_and_crlf(tmp_path) -> None:
    import gzip

    p = tmp_path / "raw.txt.gz"
    p.write_bytes(gzip.compress(("# h\r\n" + GOOD.replace("\n", "\r\n")).encode()))
    raw = read_flaser_no_timestamps(p)
    np.testing.assert_array_equal(raw.ranges, [[1, 2, 3], [1.5, 2.5, 3.5]])
    np.testing.assert_array_equal(raw.odom[1], [0.2, 0.2, 0.3])
    np.testing.assert_array_equal(raw.lines, [2, 3])


# --- relation errors of a tracked trajectory -----------------------------------------------

def _rel(a: Pose, b: Pose, t1: float, t2: float) -> Relation:
    return Relation(t1, t2, a.between(b), 0)


def test_relation_errors_of_a_hand_made_trajectory() -> None:
    """Truth: a square walked with turns (crossing ±π). The estimate equals it but for scan 3,
    moved 0.3 m along x and turned 2°: the relations (2, 3) and (3, 4) see that error, (0, 1) and
    (1, 2) none, and the relation at a stamp no row has is skipped."""
    true = [Pose(0, 0, 0), Pose(1, 0, math.pi / 2), Pose(1, 1, math.pi), Pose(0, 1, -math.pi / 2),
            Pose(0, 0, 0.0)]
    est = list(true)
    est[3] = Pose(0.3, 1, -math.pi / 2 + math.radians(2))
    stamps = np.array([100.0, 100.2, 100.4, 100.6, 100.8])
    rels = [_rel(true[i], true[j], stamps[i], stamps[j]) for i, j in ((0, 1), (1, 2), (2, 3), (3, 4))]
    rels.append(Relation(100.0, 101.0, Pose(1, 0, 0), 9))
    order = [4, 2, 0, 3, 1]  # rows in any order
    e = tracked_relation_errors(stamps[order] + 4e-6, np.array([p.as_array() for p in est])[order], rels)
    assert e.skipped == 1 and list(e.used) == [0, 1, 2, 3]
    # (2, 3): est(2)⁻¹ est(3) vs true: 0.3 m along the map's x, 2° more turn
    # (3, 4): est(3)⁻¹ est(4): the start is 0.3 m off and turned 2°, so the end moves by both
    lever = Pose(0.3, 1, -math.pi / 2 + math.radians(2)).between(true[4])
    d34 = math.hypot(*(lever.xy - true[3].between(true[4]).xy))
    np.testing.assert_allclose(e.trans_m, [0, 0, 0.3, d34], atol=1e-12)
    np.testing.assert_allclose(np.degrees(e.rot_rad), [0, 0, 2, -2], atol=1e-9)
    s = tracked_relation_stats(stamps[order], np.array([p.as_array() for p in est])[order], rels)
    assert s["n"] == 4 and s["n_relations"] == 5 and s["n_skipped"] == 1
    assert s["trans_mean_m"] == pytest.approx((0.3 + d34) / 4)
    assert s["trans_std_m"] == pytest.approx(np.std([0, 0, 0.3, d34], ddof=1))
    assert s["rot_mean_deg"] == pytest.approx(1.0) and s["rot_std_deg"] == pytest.approx(np.std([0, 0, 2, 2], ddof=1))
    none = tracked_relation_stats(stamps[:1], np.zeros((1, 3)), rels)
    assert none["n"] == 0 and none["n_skipped"] == 5 and math.isnan(none["trans_mean_m"])


def test_csail_native_names_its_relations_and_raw_odometry_scores_them(datasets) -> None:
    """Every relation's stamps are rows of real-csail-native; the raw odometry's own relation
    errors (dead reckoning) have the medians the data README states (5.0 cm, 2.1°)."""
    sc, scans = datasets["csail"]
    path = relations_path(sc)
    assert path.resolve() == (REAL / "mit-csail" / "mit-csail.relations").resolve()
    rels = read_relations(path)
    e = tracked_relation_errors(np.array([s.stamp for s in scans]), np.array([s.odom.as_array() for s in scans]),
                                rels)
    assert e.skipped == 0 and len(e.used) == 1172
    assert np.median(e.trans_m) == pytest.approx(0.050, abs=5e-4)
    assert np.degrees(np.median(np.abs(e.rot_rad))) == pytest.approx(2.1, abs=0.01)
    assert relations_path(datasets["intel"][0]) is None


def test_a_bad_relations_field_is_one_line(tmp_path) -> None:
    from tfloc.core.laser import LaserSpec
    from tfloc.io.scenario import Scenario

    sc = Scenario("x", tmp_path / "m.yaml", LaserSpec.lms200(), root=tmp_path, extra={"relations": 5})
    with pytest.raises(DatasetError, match=r"scenario.json: field 'relations' must be a path"):
        relations_path(sc)


@pytest.mark.bitwise
def test_committed_no_truth_dataset_regenerates(rebuilt: Path) -> None:
    """The bundled recording without truth is `tfloc real-data`'s too."""
    rel = Path("scenarios") / "real-csail-native-no-truth"
    assert_same_file(rebuilt / rel / "scans.csv", SCEN.parent / rel / "scans.csv")


def test_no_truth_dataset_is_the_native_recording_without_its_truth(datasets) -> None:
    """Same scans, stamps, odometry and start as real-csail-native; no true pose anywhere, and
    declared so (a robot owner's recording)."""
    sc = read_scenario(SCEN / "real-csail-native-no-truth")
    blind = read_scans(sc)
    _, native = datasets["csail"]
    assert sc.extra["truth"] is False and not sc.has_truth and sc.mode == "sequence"
    assert [s.scan_id for s in blind] == [s.scan_id for s in native]
    assert all(s.true is None for s in blind)
    assert blind[0].initial == native[0].true
    for a, b in zip(blind, native, strict=True):
        assert a.stamp == b.stamp and a.odom == b.odom
        np.testing.assert_array_equal(a.ranges, b.ranges)
