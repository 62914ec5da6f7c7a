"""README "Quick start": the block of commands after `make` runs as printed (in a directory with
the project's data and environment, `source .venv/bin/activate` first), and the two commands and
`make quick` name targets the Makefile has."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from _paths import ROOT


def _quick_start_blocks() -> list[str]:
    text = (ROOT / "README.md").read_text()
    section = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```sh\n(.*?)```", section, flags=re.S)


def test_the_two_commands_are_make_targets() -> None:
    make_block, _ = _quick_start_blocks()
    targets = [ln.split()[1] for ln in make_block.splitlines() if ln.startswith("make ")]
    assert targets == ["bench", "test"]
    for t in (*targets, "quick"):
        r = subprocess.run(["make", "-n", t], cwd=ROOT, capture_output=True, text=True, timeout=60)
        assert r.returncode == 0, (t, r.stderr)
    assert "make test" in (ROOT / ".ci" / "run").read_text()


def test_the_command_line_block_runs_as_printed(tmp_path: Path) -> None:
    _, block = _quick_start_blocks()
    assert block.startswith("source .venv/bin/activate")
    (tmp_path / "data").symlink_to(ROOT / "data")
    (tmp_path / ".venv").symlink_to(Path(sys.executable).parents[1])
    r = subprocess.run(["bash", "-e", "-c", block], cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    assert re.search(r"^tfloc \d", r.stdout, re.M) and "Presets" in r.stdout
    assert (tmp_path / "est.csv").read_text().count("\n") == 6 and (tmp_path / "track.csv").is_file()
    assert "score: tracked" in r.stderr
