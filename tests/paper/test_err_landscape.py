"""Err around a pose on the test room: the truth is the grid's lowest point, walls are NaN."""

from __future__ import annotations

import numpy as np
import pytest

from tfloc import Pose, Problem
from tfloc.paper.landscape import err_landscape, local_minima
from tfloc.paper.matcher import TfConfig

TRUE = Pose(3.0, 3.5, 0.4)


@pytest.mark.parametrize("config", [TfConfig(), TfConfig(err_norm="l1")], ids=["l2", "l1"])
def test_noise_free_scan_has_its_minimum_at_the_truth(test_room, lms200, config):
    problem = Problem(test_room, lms200, test_room.raycast(TRUE, lms200), TRUE)
    land = err_landscape(problem, TRUE, half_width_m=0.5, n=11, config=config)
    assert land.err.shape == (11, 11) and land.theta == TRUE.theta
    assert land.xs[5] == pytest.approx(TRUE.x) and land.ys[5] == pytest.approx(TRUE.y)
    assert land.err[5, 5] == pytest.approx(0.0, abs=1e-9)          # the real scan itself
    assert np.nanmin(land.err) == land.err[5, 5] and local_minima(land.err)[5, 5]
    far = land.distance_to(TRUE.x, TRUE.y) > 0.3
    assert np.nanmedian(land.err[far]) > 0.05                       # away from the truth Err grows


def test_positions_in_obstacles_are_nan(test_room, lms200):
    problem = Problem(test_room, lms200, test_room.raycast(TRUE, lms200), TRUE)
    land = err_landscape(problem, Pose(2.0, 1.4, 0.0), half_width_m=0.05, n=3)   # inside the table
    assert np.isnan(land.err[1, 1])


def test_local_minima_on_a_hand_made_grid():
    e = np.array([[3.0, 2.0, 3.0, 4.0],
                  [2.0, 1.0, 2.0, 4.0],
                  [3.0, 2.0, 3.0, 0.5],
                  [np.nan, 3.0, 4.0, 1.0]])
    np.testing.assert_array_equal(np.argwhere(local_minima(e)), [[1, 1], [2, 3]])


def test_report_draws_tf_objective_around_the_truth(tmp_path):
    """A run with tf gets the landscape section: a figure and one row per drawn scan."""
    from tfloc.cli.report import make_report as write_report
    from tfloc.harness.config import MatcherSpec, RunConfig
    from tfloc.harness.runner import run

    root = __import__("pathlib").Path(__file__).resolve().parents[2]
    cfg = RunConfig("t", tmp_path / "run", (root / "data" / "scenarios" / "office-pool",),
                    (MatcherSpec.make("tf"),), jobs=1, limit_per_group=1)
    out = run(cfg, progress=False)
    write_report(out)
    text = (out / "report.md").read_text()
    assert "## Why `tf` fails: its objective around the truth" in text
    assert (out / "figures" / "err_landscape.png").is_file()
    assert text.count("| office-pool/d") >= 3
