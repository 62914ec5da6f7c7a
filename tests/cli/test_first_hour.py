"""A new user's first hour: --version, the list of matchers and presets, a scored track, "did you
mean" for matchers and datasets, a plugin's bad parameter as one line, the default matchers of a
dataset's mode and help text that reads as written."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from _paths import ROOT

from tfloc.cli import build_parser
from tfloc.cli.bench import config_from_args
from tfloc.core.matcher import GLOBAL, default_matchers, factory_of, kind_of

ENV = {**os.environ, "COLUMNS": "100", "PYTHONPATH": os.pathsep.join([str(ROOT / "tests"), str(ROOT)])}


def tfloc(*args: str, cwd: Path = ROOT, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "tfloc.cli", *args], cwd=cwd, env=env or ENV,
                          capture_output=True, text=True, timeout=600)


def one_line(r: subprocess.CompletedProcess) -> str:
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    return lines[0]


def test_version_names_the_release_and_commit() -> None:
    r = tfloc("--version")
    assert r.returncode == 0 and re.match(r"tfloc \d+\.\d+\.\d+", r.stdout), r.stdout


def test_matchers_lists_every_matcher_and_preset_with_its_kind() -> None:
    r = tfloc("matchers")
    assert r.returncode == 0, r.stderr
    lines = {ln.split()[0]: ln for ln in r.stdout.splitlines() if ln and not ln[0].isspace()}
    assert "single-scan" in lines["csm-corr"] and "tracker" in lines["amcl"] and "global" in lines["tf-global"]
    assert "tracker" in lines["amcl-tuned"] and "single-scan" in lines["tf-plus-changed"]
    assert "tracker" in lines["odometry"]


def test_matchers_name_shows_parameters_with_defaults_and_units() -> None:
    r = tfloc("matchers", "csm-corr")
    assert r.returncode == 0, r.stderr
    window = next(ln for ln in r.stdout.splitlines() if ln.startswith("window_xy "))
    assert "3.5" in window and "metres" in window
    preset = tfloc("matchers", "amcl-tuned")
    assert "preset of amcl" in preset.stdout and "alpha1=0.26" in preset.stdout
    assert re.search(r"^alpha1\s+0\.26\s", preset.stdout, re.M)  # the preset's value as the default
    bad = tfloc("matchers", "csm-cor")
    assert "did you mean 'csm-corr'" in one_line(bad)


def test_track_prints_its_score_where_the_dataset_has_truth(tmp_path: Path) -> None:
    r = tfloc("track", "--dataset", "data/scenarios/seq-quick", "--matcher", "odometry", "--out",
              str(tmp_path / "dr.csv"))
    assert r.returncode == 0, r.stderr
    score = r.stderr.strip().splitlines()[-1]
    assert re.match(r"score: tracked \d+\.\d % of \d+ scans with truth", score), score
    assert "APE RMSE" in score and "losses" in score and "jumps > 1 m" in score


def test_a_misspelled_dataset_or_matcher_gets_the_close_names(tmp_path: Path) -> None:
    line = one_line(tfloc("bench", "data/scenarios/detial-1", "--matchers", "tf", "--out", str(tmp_path / "r")))
    assert "data/scenarios/detial-1: no such directory; did you mean data/scenarios/detail-1" in line
    line = one_line(tfloc("bench", "data/scenarios/detail-1", "--matchers", "csm-cor", "--out", str(tmp_path / "r")))
    assert "unknown matcher 'csm-cor'; did you mean 'csm-corr'" in line
    line = one_line(tfloc("track", "--dataset", "data/scenarios/seq-quick", "--matcher", "amcl-tunde"))
    assert "did you mean 'amcl-tuned'" in line


def test_a_plugin_that_rejects_a_value_the_python_way_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "strict_plugin.py").write_text(
        "class Strict:\n    name = 'strict'\n    def __init__(self, iterations=10):\n"
        "        self.iterations = int(iterations)\n    def localize(self, problem):\n"
        "        raise NotImplementedError\n")
    env = {**ENV, "PYTHONPATH": os.pathsep.join([str(tmp_path), ENV["PYTHONPATH"]])}
    cfg = tmp_path / "run.toml"
    cfg.write_text(f'datasets = ["{ROOT}/data/scenarios/detail-1"]\nout = "{tmp_path}/run"\n'
                   'matchers = [{ label = "s", name = "strict_plugin:Strict", params = { iterations = "many" } }]\n')
    line = one_line(tfloc("bench", str(cfg), "--allow-import", env=env))
    assert "matchers[0]" in line and "'strict_plugin:Strict'" in line and "invalid literal for int()" in line
    assert not (tmp_path / "run").exists()


def test_the_default_matchers_solve_the_datasets_mode() -> None:
    single = default_matchers({"single"})
    assert "csm-corr" in single and "tf" in single
    assert not {"amcl", "tf-plus-track", "odometry", "tf-global", "bnb-global"} & set(single)
    assert {"amcl", "tf-plus-track", "csm-corr"} <= set(default_matchers({"sequence"}))
    globals_ = default_matchers({"global"})   # every global matcher, whatever is registered
    assert {"tf-global", "bnb-global"} <= set(globals_)
    assert all(kind_of(factory_of(m)) == GLOBAL for m in globals_)
    args = build_parser().parse_args(["bench", str(ROOT / "data/scenarios/detail-1")])
    assert [m.name for m in config_from_args(args).matchers] == single


@pytest.mark.parametrize("command", ["bench", "track", "localize", "import-bag", "matchers"])
def test_help_text_reads_as_written(command: str) -> None:
    r = tfloc(command, "--help")
    assert r.returncode == 0, r.stderr
    assert not re.search(r"[a-z]-\n\s+[a-z]", r.stdout), "a name broken across lines"
    for line in r.stdout.splitlines():
        if line.lstrip().startswith("tfloc "):  # an example: no padding runs, continuation lines kept
            assert not re.search(r"\S {4,}\S", line), line
