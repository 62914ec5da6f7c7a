"""A rerun never reuses rows made by other code: a run records what answers (tfloc's answering
source; a plugin's distribution, version and source), a rerun after a code change stops with one
line naming it, and a complete run of the same code says so."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from _paths import ROOT

from tfloc.harness import identity
from tfloc.harness.fingerprint import differences

PROBE = '''
from tfloc import Estimate, Pose


class Probe:
    name = "probe"

    def localize(self, problem):
        g = problem.initial
        return Estimate(Pose(g.x + {shift}, g.y, g.theta), converged=True)
'''


def _bench(tmp: Path, *extra: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp / "plugin"), str(ROOT / "tests")])}
    return subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", str(ROOT / "data/scenarios/detail-1"),
                           "--matchers", "byo_probe:Probe", "--allow-import", "--limit-per-group", "1",
                           "--out", str(tmp / "run"), "--jobs", "1", "--no-progress", *extra],
                          cwd=tmp, env=env, capture_output=True, text=True, timeout=600)


def test_a_changed_plugin_is_not_resumed(tmp_path: Path) -> None:
    plugin = tmp_path / "plugin"
    plugin.mkdir()
    (plugin / "byo_probe.py").write_text(PROBE.format(shift="0.0"))
    first = _bench(tmp_path)
    assert first.returncode == 0, first.stderr
    fp = json.loads((tmp_path / "run" / "run.json").read_text())["fingerprint"]
    code = fp["matchers"]["byo_probe:Probe"]
    assert code["code"] == "plugin" and code["module"] == "byo_probe" and len(code["source"]) == 64
    assert fp["tfloc"]["source"] == identity.tfloc_code()["source"]
    again = _bench(tmp_path)
    assert again.returncode == 0 and "already complete: 0 tasks run" in again.stderr, again.stderr
    (plugin / "byo_probe.py").write_text(PROBE.format(shift="0.5"))  # the answer moves half a metre
    changed = _bench(tmp_path)
    lines = changed.stderr.strip().splitlines()
    assert changed.returncode == 2 and len(lines) == 1 and "Traceback" not in changed.stderr, changed.stderr
    assert "byo_probe:Probe: source changed" in lines[0] and "--regenerate" in lines[0]
    redo = _bench(tmp_path, "--regenerate")
    assert redo.returncode == 0, redo.stderr
    rows = (tmp_path / "run" / "estimates.csv").read_text().splitlines()
    header = rows[0].split(",")
    est_x, init_x = header.index("est_x"), header.index("init_x")
    assert all(abs(float(r.split(",")[est_x]) - float(r.split(",")[init_x]) - 0.5) < 1e-6 for r in rows[1:])


def _fp(source: str, matchers: dict | None = None) -> dict:
    return {"tfloc": {"version": "0.1.0", "source": source}, "datasets": {}, "success": {},
            "matchers": matchers or {"tf": {"name": "tf", "matcher": "tf", "params": {}, "code": "tfloc"}}}


def test_a_change_of_tfloc_code_is_named() -> None:
    assert differences(_fp("a" * 64), _fp("a" * 64)) == []
    (line,) = differences(_fp("a" * 64), _fp("b" * 64))
    assert line.startswith("tfloc's code changed (source aaaaaaaaaaaa → bbbbbbbbbbbb")
    (old,) = differences({**_fp("a" * 64), "tfloc": "0.1.0"}, _fp("a" * 64))
    assert "recorded no code identity" in old


def test_a_plugin_version_change_is_named() -> None:
    def plug(version: str, source: str) -> dict:
        return {"p": {"name": "m:P", "matcher": "m:P", "params": {}, "code": "plugin", "module": "m",
                      "distribution": "my-matcher", "version": version, "source": source}}
    assert differences(_fp("a", plug("0.1", "s")), _fp("a", plug("0.2", "s"))) == ["p: my-matcher 0.1 → my-matcher 0.2"]
    assert differences(_fp("a", plug("0.1", "s")), _fp("a", plug("0.1", "t"))) == ["p: source changed"]


def test_the_answering_code_leaves_out_the_presentation_layers() -> None:
    files = identity.tfloc_files()
    assert "tfloc/paper/corners.py" in files and "tfloc/presets.toml" in files
    assert any(f.startswith("tfloc/baselines/") for f in files)
    assert not any(f.split("/")[1] in identity.PRESENTATION for f in files)


def test_git_state_names_the_checkout_of_the_code() -> None:
    state = identity.git_state()
    assert set(state) == {"commit", "dirty"}
    if state["commit"] is not None:
        assert len(state["commit"]) == 40 and isinstance(state["dirty"], bool)
