"""README "Bring your own matcher", run exactly as printed: the module and pyproject.toml are
taken from the README's code blocks, installed as a package (into a temporary directory, not
the project's environment: the printed ``pip install -e`` would register it for good), and the
printed ``tfloc bench`` and ``tfloc report`` commands are run unchanged; the new matcher runs
beside the others and is found by the registry."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _blocks() -> dict[str, str]:
    text = (ROOT / "README.md").read_text()
    section = text.split("## Bring your own matcher", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```(\w+)\n(.*?)```", section, flags=re.S)
    return {lang: body for lang, body in blocks}


def test_readme_example_runs_as_printed(tmp_path: Path) -> None:
    blocks = _blocks()
    assert {"python", "toml", "sh"} <= set(blocks)
    pkg = tmp_path / "my-matcher"
    pkg.mkdir()
    (pkg / "my_matcher.py").write_text(blocks["python"])
    (pkg / "pyproject.toml").write_text(blocks["toml"])
    commands = [c for c in blocks["sh"].splitlines() if c.strip()]
    assert commands[0] == "pip install --no-deps -e my-matcher"
    site = tmp_path / "site"
    pip = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps",
                          "--target", str(site), str(pkg)], capture_output=True, text=True, timeout=300)
    if pip.returncode != 0:
        pytest.fail(f"installing the README's package failed: {pip.stderr[-2000:]}")
    (tmp_path / "data").symlink_to(ROOT / "data")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")]))
    tfloc = str(Path(sys.executable).with_name("tfloc"))
    for line in commands[1:]:
        argv = shlex.split(line)
        assert argv[0] == "tfloc"
        proc = subprocess.run([tfloc, *argv[1:]], cwd=tmp_path, env=env, capture_output=True, text=True,
                              timeout=900)
        assert proc.returncode == 0, (line, proc.stderr[-3000:])
    est = (tmp_path / "results" / "my-grid" / "estimates.csv").read_text()
    rows = [r for r in est.splitlines()[1:] if ",my-grid," in r]
    assert len(rows) == 2 * 9 and all(",ok," in r for r in rows)
    report = (tmp_path / "results" / "my-grid" / "report.md").read_text()
    assert "`my-grid`" in report
