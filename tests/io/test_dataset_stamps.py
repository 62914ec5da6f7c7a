"""The optional ``stamp`` column of scans.csv: written only when some scan has a stamp, read
back into Scan.stamp, checked like any number; datasets without it are unchanged."""

from __future__ import annotations

import numpy as np
import pytest
from _paths import MAPS

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.errors import DatasetError
from tfloc.io.scenario import Scan, read_scans, read_scenario, write_scenario

MAP = MAPS / "test-room.geojson"
LASER = LaserSpec.lms200()


def _scans(stamps) -> list[Scan]:
    return [Scan(f"s{k}", "g", np.full(LASER.n_beams, 2.0 + k), Pose(1.0, 2.0, 0.1), Pose(1.1, 2.0, 0.0), stamp=s)
            for k, s in enumerate(stamps)]


def test_stamps_round_trip(tmp_path) -> None:
    write_scenario(tmp_path / "a", "a", MAP, LASER, _scans([1_700_000_000.123456, None, 5.5]))
    header = (tmp_path / "a" / "scans.csv").read_text().splitlines()[0]
    assert header.endswith(",ranges,stamp")
    got = [s.stamp for s in read_scans(read_scenario(tmp_path / "a"))]
    assert got == [pytest.approx(1_700_000_000.123456, abs=1e-6), None, 5.5]


def test_no_stamps_no_column(tmp_path) -> None:
    write_scenario(tmp_path / "b", "b", MAP, LASER, _scans([None, None]))
    assert (tmp_path / "b" / "scans.csv").read_text().splitlines()[0] == \
        "scan_id,group,true_x,true_y,true_theta,init_x,init_y,init_theta,ranges"
    assert all(s.stamp is None for s in read_scans(read_scenario(tmp_path / "b")))


@pytest.mark.parametrize("bad", ["soon", "inf"])
def test_bad_stamp_names_the_line(tmp_path, bad) -> None:
    write_scenario(tmp_path / "c", "c", MAP, LASER, _scans([1.0, 2.0]))
    p = tmp_path / "c" / "scans.csv"
    p.write_text(p.read_text().replace(",2.000000\n", f",{bad}\n"))
    with pytest.raises(DatasetError, match=r"scans.csv:3: (column 'stamp' is not a number|stamp is not finite)"):
        read_scans(read_scenario(tmp_path / "c"))
