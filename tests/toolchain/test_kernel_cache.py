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
    kept = _kernel_cache.source_hash([tmp_path], ("report",))
    (tmp_path / "report").mkdir()
    (tmp_path / "report" / "c.py").write_text("z = 1\n")       # a presentation layer: no kernel
    assert _kernel_cache.source_hash([tmp_path], ("report",)) == kept


def test_this_process_caches_under_its_source_version() -> None:
    here = Path(numba.config.CACHE_DIR)
    if os.environ.get("NUMBA_CACHE_DIR") != os.environ.get("TFLOC_NUMBA_CACHE_DIR"):
        pytest.skip("the user chose numba's cache directory")
    assert here.name == _kernel_cache.source_hash(_kernel_cache._roots(), _kernel_cache.PRESENTATION)
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


def test_kernels_imported_after_a_thread_limit_still_cache_under_the_source_version(
        tmp_path: Path) -> None:
    """limit_threads changes the environment and numba re-reads its settings from it; the
    directory must survive that (it once fell back to the source folders' ``__pycache__``,
    where a cached caller keeps its callees' old code)."""
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path)}
    for var in ("NUMBA_CACHE_DIR", "TFLOC_NUMBA_CACHE_DIR"):
        env.pop(var, None)
    code = ("import numba, tfloc\n"
            "from tfloc.harness.threads import limit_threads\n"
            "limit_threads(1)\n"
            "import numba.core.config\n"
            "numba.core.config.reload_config()\n"
            "import tfloc.paper.kernels as k\n"
            "print(numba.config.CACHE_DIR)\n"
            "print(k.function1_kernel._cache._cache_path)\n")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout.split()
    here = tmp_path / "tfloc" / "numba" / _kernel_cache.source_hash(_kernel_cache._roots(), _kernel_cache.PRESENTATION)
    assert Path(out[0]) == here
    assert Path(out[1]).parent == here


def test_a_child_process_picks_its_own_source_version_not_its_parents(tmp_path: Path) -> None:
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "child"),
           "NUMBA_CACHE_DIR": str(tmp_path / "parent-version"),
           "TFLOC_NUMBA_CACHE_DIR": str(tmp_path / "parent-version")}
    code = "import numba, tfloc; print(numba.config.CACHE_DIR)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout.strip()
    assert Path(out).parent == tmp_path / "child" / "tfloc" / "numba"
