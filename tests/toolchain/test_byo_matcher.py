"""README "Bring your own matcher", run as printed: the module and pyproject.toml are taken from
the README's code blocks; the no-install commands run unchanged (a parameter outside its rule
exits 2 with one line, as the block's comment says); the package is installed (into a temporary
directory, not the project's environment: the printed ``.venv/bin/pip install -e`` would
register it for good) and the printed ``tfloc bench`` and ``tfloc report`` commands run
unchanged; the new matcher runs beside the others and is found by the registry."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from _paths import ROOT


def _blocks() -> list[tuple[str, str]]:
    text = (ROOT / "README.md").read_text()
    section = text.split("## Bring your own matcher", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```(\w+)\n(.*?)```", section, flags=re.S)


def _lines(block: str) -> list[str]:
    return [c for c in block.splitlines() if c.strip()]


def _sh(line: str, cwd: Path, env: dict) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", "-c", line], cwd=cwd, env=env, capture_output=True, text=True, timeout=900)


@pytest.fixture()
def workdir(tmp_path: Path) -> Path:
    """A directory like the README's reader's: the project's data and environment beside the
    package the README writes."""
    (tmp_path / "data").symlink_to(ROOT / "data")
    (tmp_path / ".venv").symlink_to(Path(sys.executable).parents[1])
    pkg = tmp_path / "my-matcher"
    pkg.mkdir()
    blocks = dict((lang, body) for lang, body in _blocks() if lang in ("python", "toml"))
    (pkg / "my_matcher.py").write_text(blocks["python"])
    (pkg / "pyproject.toml").write_text(blocks["toml"])
    return tmp_path


def test_the_no_install_route_runs_as_printed(workdir: Path) -> None:
    first_sh = next(body for lang, body in _blocks() if lang == "sh")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    for line in _lines(first_sh):
        expect = re.search(r"# exits (\d+)", line)
        r = _sh(line, workdir, env)
        assert r.returncode == (int(expect.group(1)) if expect else 0), (line, r.stderr[-3000:])
        if expect:
            err = r.stderr.strip().splitlines()
            assert len(err) == 1 and "span must be >= 1" in err[0], r.stderr
    est = (workdir / "results" / "my-grid-try" / "estimates.csv").read_text()
    assert sum(",my_matcher:GridSearchMatcher," in r for r in est.splitlines()) == 9


def test_the_registered_route_runs_as_printed(workdir: Path) -> None:
    last_sh = [body for lang, body in _blocks() if lang == "sh"][-1]
    commands = _lines(last_sh)
    assert commands[0] == ".venv/bin/pip install --no-deps -e my-matcher"
    site = workdir / "site"
    pip = subprocess.run([sys.executable, "-m", "pip", "install", "-qq", "--no-deps", "--target", str(site),
                          str(workdir / "my-matcher")], capture_output=True, text=True, timeout=300)
    if pip.returncode != 0:
        pytest.fail(f"installing the README's package failed: {pip.stderr[-2000:]}")
    env = {**os.environ, "PYTHONPATH": str(site)}
    for line in commands[1:]:
        assert line.startswith(".venv/bin/tfloc ")
        r = _sh(line, workdir, env)
        assert r.returncode == 0, (line, r.stderr[-3000:])
    est = (workdir / "results" / "my-grid" / "estimates.csv").read_text()
    rows = [r for r in est.splitlines()[1:] if ",my-grid," in r]
    assert len(rows) == 2 * 9 and all(",ok," in r for r in rows)
    report = (workdir / "results" / "my-grid" / "report.md").read_text()
    assert "`my-grid`" in report
