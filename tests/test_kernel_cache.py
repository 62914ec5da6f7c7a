"""numba's cache is kept per version of tfloc's source (tfloc._kernel_cache)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numba
import pytest

from tfloc import _kernel_cache


def test_the_source_hash_follows_every_file(tmp_path: Path) -> None:
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "b.py").write_text("y = 2\n")
    first = _kernel_cache.source_hash([tmp_path])
    assert _kernel_cache.source_hash([tmp_path]) == first
    (tmp_path / "sub" / "b.py").write_text("y = 3\n")           # a callee's module changes
    assert _kernel_cache.source_hash([tmp_path]) != first


def test_this_process_caches_under_its_source_version() -> None:
    here = Path(numba.config.CACHE_DIR)
    if os.environ.get("NUMBA_CACHE_DIR"):
        pytest.skip("the user chose numba's cache directory")
    assert here.name == _kernel_cache.source_hash(_kernel_cache._roots())
    assert here.parent.name == "numba" and here.parent.parent.name == "tfloc"


def test_a_chosen_directory_is_kept_and_old_versions_are_pruned(tmp_path: Path) -> None:
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path)}
    env.pop("NUMBA_CACHE_DIR", None)
    base = tmp_path / "tfloc" / "numba"
    for i in range(_kernel_cache.KEEP + 3):                      # caches of other versions
        (base / f"old{i}").mkdir(parents=True)
        os.utime(base / f"old{i}", (1000 + i, 1000 + i))
    code = "import numba, tfloc; print(numba.config.CACHE_DIR)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout.strip()
    assert Path(out).parent == base
    kept = sorted(d.name for d in base.iterdir() if d.name.startswith("old"))
    assert kept == [f"old{i}" for i in range(3, _kernel_cache.KEEP + 3)]    # the newest KEEP
    chosen = tmp_path / "mine"
    out = subprocess.run([sys.executable, "-c", code], env={**env, "NUMBA_CACHE_DIR": str(chosen)},
                         capture_output=True, text=True, check=True).stdout.strip()
    assert Path(out) == chosen
