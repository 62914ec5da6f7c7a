"""mrpt-pf: MRPT's pf-localization as an external program. The file formats (pure) always; one real
run on a few scans where Debian's mrpt-apps is installed (else skipped, saying so)."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
from _paths import ROOT
from tfloc.baselines._mrpt_files import carmen_lines, parse_estimates, render_ini

from tfloc.core.laser import LaserSpec
from tfloc.core.matcher import get_matcher, kind_of
from tfloc.errors import ParameterError
from tfloc.harness.track import track
from tfloc.io.scenario import read_scans, read_scenario, write_scenario

QUICK = ROOT / "data" / "scenarios" / "seq-quick"
MISSING = next((p for p in ("pf-localization", "carmen2rawlog", "ros-map-yaml2mrpt") if shutil.which(p) is None), None)
needs_mrpt = pytest.mark.skipif(MISSING is not None, reason=f"{MISSING} not installed (Debian: apt-get install mrpt-apps)")


def test_render_ini_replaces_adds_and_keeps_the_rest():
    text = "# head\n[A]\nk1=1   // note\nk2 = 2\n[B]\nx=0\n"
    out = render_ini(text, {("A", "k2"): 5, ("A", "new"): True, ("B", "x"): 0.25, ("C", "y"): "p"})
    assert out.splitlines() == ["# head", "[A]", "k1=1   // note", "k2=5", "new=true", "[B]", "x=0.25", "[C]", "y=p"]


def test_carmen_lines_carry_the_laser_and_odometry():
    laser = LaserSpec.from_degrees(10.0, 179.0, 1.0, -90.0)
    r = np.full(laser.n_beams, 2.0)
    r[0], r[1], r[2] = np.inf, 12.0, -1.0
    (line,) = carmen_lines(laser, [r], np.array([3.5]), np.array([[1.0, 2.0, 0.5]]))
    f = line.split()
    assert f[0] == "ROBOTLASER1" and float(f[2]) == pytest.approx(-math.pi / 2, abs=1e-6)
    assert float(f[3]) == pytest.approx(math.radians(179), abs=1e-6) and int(f[8]) == laser.n_beams
    beams = [float(v) for v in f[9:9 + laser.n_beams]]
    assert beams[:4] == [10.0, 10.0, 10.0, 2.0]  # no returns at the maximum range
    assert f[9 + laser.n_beams:9 + laser.n_beams + 7] == ["0", "1", "2", "0.5", "1", "2", "0.5"]


def test_parse_estimates_reads_means_in_radians_and_spread():
    log = ("[INFO] Odometry estimation: (0.1,0.2,3.00deg)\n"
           "[INFO] PDF estimation: (1.500,-2.250,90.00deg), ESS (B.R.)= 0.5 tr(cov): 0.125\n"
           "[INFO] PDF estimation: (1.600,-2.250,-45.00deg), ESS (B.R.)= 0.4 tr(cov): 0.0625\n")
    poses, spread = parse_estimates(log)
    assert poses == pytest.approx(np.array([[1.5, -2.25, math.pi / 2], [1.6, -2.25, -math.pi / 4]]))
    assert spread == pytest.approx([0.125, 0.0625])


@needs_mrpt
def test_bad_parameter_is_refused_naming_it():
    with pytest.raises(ParameterError, match="pf_algorithm"):
        get_matcher("mrpt-pf", pf_algorithm=7)


@needs_mrpt
def test_mrpt_pf_tracks_a_few_scans(tmp_path):
    sc = read_scenario(QUICK)
    root = write_scenario(tmp_path / "q", "q", sc.map_path, sc.laser, read_scans(sc)[:15], mode="sequence")
    sc = read_scenario(root)
    scans = read_scans(sc)
    m = get_matcher("mrpt-pf", particles_count=2000, kld_max_samples=2000)
    assert kind_of(m) == "tracker" and m.program.identity()["package"] == "mrpt-apps"
    rows = track(sc, scans, m)
    assert [r.status.ok for r in rows] == [True] * len(scans)
    err = np.array([r.dist_err_m for r in rows])
    assert np.all(err < 0.15), err  # seq-quick is easy: the filter stays within 15 cm of the truth
    assert all(r.cpu_s > 0 for r in rows) and rows[0].info["cpu_from"] == "own-log"
    assert all(r.info["sqrt_tr_cov"] >= 0 for r in rows)


def test_missing_program_is_one_line_naming_the_package(monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(Exception, match=r"pf-localization not found on PATH \(Debian: apt-get install mrpt-apps\)") as e:
        get_matcher("mrpt-pf")
    assert "\n" not in str(e.value)
