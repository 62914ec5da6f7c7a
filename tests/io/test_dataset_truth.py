"""A dataset without truth says so: ``"truth": false`` in scenario.json (as import-bag writes
it without reference poses), read by :attr:`Scenario.has_truth` (from the rows where not
declared); a declared ``false`` with a true pose in a row, or a ``truth`` that is not a
boolean, is a one-line error."""

from __future__ import annotations

import json

import pytest
from _paths import ROOT

from tfloc.errors import DatasetError
from tfloc.io.scenario import Scan, read_scans, read_scenario, write_scenario

QUICK = ROOT / "data" / "scenarios" / "seq-quick"


def _write(tmp_path, blank: bool, **extra):
    sc = read_scenario(QUICK)
    scans = read_scans(sc)[:4]
    if blank:
        scans = [Scan(s.scan_id, s.group, s.ranges, s.initial, None, stamp=s.stamp, odom=s.odom) for s in scans]
    return write_scenario(tmp_path / "d", "d", sc.map_path, sc.laser, scans, mode="sequence", **extra)


def test_has_truth_is_declared_or_read_from_the_rows(tmp_path):
    assert read_scenario(QUICK).has_truth is True
    assert read_scenario(ROOT / "data" / "scenarios" / "real-csail-native").has_truth is True  # 406 of 1927 rows
    assert read_scenario(_write(tmp_path / "a", blank=True)).has_truth is False
    sc = read_scenario(_write(tmp_path / "b", blank=True, truth=False))
    assert sc.has_truth is False and len(read_scans(sc)) == 4


def test_a_declared_false_truth_is_checked(tmp_path):
    sc = read_scenario(_write(tmp_path / "a", blank=False, truth=False))
    with pytest.raises(DatasetError, match=r"scans.csv:2: a true pose in a dataset whose scenario.json says "
                                           r"\"truth\": false"):
        read_scans(sc)
    root = _write(tmp_path / "b", blank=True)
    doc = json.loads((root / "scenario.json").read_text())
    (root / "scenario.json").write_text(json.dumps({**doc, "truth": "no"}))
    with pytest.raises(DatasetError, match=r"field 'truth' must be true or false, got 'no'"):
        read_scenario(root)
