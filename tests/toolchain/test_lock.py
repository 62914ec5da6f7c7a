"""requirements.lock: what make installs, read for the Python a run used, and the report's note
when a run was made with other versions."""

from __future__ import annotations

import platform
from importlib import metadata

import pytest
from _paths import ROOT
from packaging.utils import canonicalize_name

from tfloc.errors import ConfigError
from tfloc.io.lock import LOCK_NAME, find_lock, lock_differences, read_lock
from tfloc.report.provenance import lock_note


def test_the_checkout_has_its_lock() -> None:
    assert find_lock() == ROOT / LOCK_NAME


def test_markers_are_evaluated_for_the_runs_python() -> None:
    a, b = read_lock(ROOT / LOCK_NAME, "3.11.7"), read_lock(ROOT / LOCK_NAME, "3.13.1")
    assert "numpy" in a and "numba" in a and "evo" in a
    assert "karto-scanmatcher" in a and "karto-scanmatcher" not in b   # wheels for ≤ 3.11 only


def test_this_environment_is_the_lock() -> None:
    """make installs exactly the lock's versions (pip install --no-deps --require-hashes -r requirements.lock)."""
    lock = read_lock(ROOT / LOCK_NAME, platform.python_version())
    installed = {canonicalize_name(d.metadata["Name"]): d.version for d in metadata.distributions()}
    wrong = {k: (installed.get(k), v) for k, v in lock.items() if installed.get(k) != v}
    assert not wrong, f"installed ≠ {LOCK_NAME}: {wrong}"


def test_a_malformed_lock_line_is_named(tmp_path) -> None:
    (tmp_path / "lock").write_text("numpy==2.4.6 \\\n    --hash=sha256:00\nnumpy>=2\n")
    with pytest.raises(ConfigError, match=r"lock:3: not a pinned requirement"):
        read_lock(tmp_path / "lock")


def test_the_report_says_when_a_run_used_other_versions() -> None:
    lock = read_lock(ROOT / LOCK_NAME, "3.11.7")
    from tfloc.core.run import Machine, RunRecord

    same = RunRecord(versions={"numpy": lock["numpy"], "tfloc": "0.1.0"}, machine=Machine(python="3.11.7"))
    assert lock_note(same) == [f"- Versions: those of `{LOCK_NAME}`"]
    other = RunRecord(versions={"numpy": "1.26.0", "numba": lock["numba"]}, machine=Machine(python="3.11.7"))
    (line,) = lock_note(other)
    assert "other than" in line and f"numpy 1.26.0 (lock {lock['numpy']})" in line and "numba" not in line
    assert lock_differences({"karto-scanmatcher": None}, lock) == {"karto-scanmatcher": (None, "1.0.0")}
    assert lock_note(RunRecord()) == []
