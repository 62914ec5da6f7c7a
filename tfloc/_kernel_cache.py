"""Where numba keeps tfloc's compiled kernels: one directory per version of tfloc's source.

numba's on-disk cache (``@njit(cache=True)``) checks only the source file of the function it
compiled. A kernel that calls a kernel of another module keeps, in its cached machine code, the
callee as it was when it was compiled: after an edit of ``maps/_raycast.py`` the cached kernels
of ``tfplus/`` and ``paper/`` went on casting rays the old way (so measurements compared old
code with old code), and a cached caller of a changed callee can crash. So, unless the user
chose a directory (``NUMBA_CACHE_DIR``), the cache lives in
``$XDG_CACHE_HOME/tfloc/numba/<hash of tfloc's source>`` (``~/.cache`` when unset): any change of
the source starts a fresh cache, and each version's cache stays valid (the presentation layers,
:data:`PRESENTATION`, hold no kernel and feed none: they are left out). The last few are kept.

The directory is also put in the environment (``NUMBA_CACHE_DIR``). numba reads its settings from
the environment again whenever the environment has changed (``numba.core.config.reload_config``,
called by :func:`tfloc.harness.threads.limit_threads` and by numba's compiler): a directory set
in ``numba.config`` alone was then dropped, and every kernel module imported after a thread limit
was cached in its own ``__pycache__``, per source file, where a caller kept its callees' old code
(the harness's timing pass measured `tf` with a ray caster two commits old). A child process
inherits the variable; ``TFLOC_NUMBA_CACHE_DIR`` marks it as tfloc's own, so the child still
picks the directory of its own source version, and a directory the user chose is left alone.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
from pathlib import Path

KEEP = 4  # cache directories of other source versions kept (most recently used)
#: top-level folders of the package that draw results and parse commands: no kernel, no constant
#: a kernel reads (also left out of a run's code identity, :mod:`tfloc.harness.identity`)
PRESENTATION = ("report", "cli", "site")
_MARK = "TFLOC_NUMBA_CACHE_DIR"  # NUMBA_CACHE_DIR as tfloc set it (not the user's choice)


def source_hash(roots: list[Path], leave_out: tuple[str, ...] = ()) -> str:
    """A hash of every ``.py`` file under the ``roots`` (but those in a top-level folder named in
    ``leave_out``): names and contents."""
    h = hashlib.sha1()
    for root in roots:
        for path in sorted(root.rglob("*.py")):
            if path.relative_to(root).parts[0] in leave_out:
                continue
            h.update(path.relative_to(root).as_posix().encode())
            h.update(b"\0")
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _roots() -> list[Path]:
    """tfloc's source folders: the package and ``tfloc.baselines`` (a folder of its own in a
    source checkout), found without importing the latter."""
    roots = [Path(__file__).resolve().parent]
    try:
        spec = importlib.util.find_spec("tfloc.baselines")
    except (ImportError, ValueError):
        spec = None
    for where in (spec.submodule_search_locations or []) if spec else []:
        path = Path(where).resolve()
        if path != roots[0] and roots[0] not in path.parents:
            roots.append(path)
    return roots


def configure() -> str | None:
    """Point numba's cache at this source version's directory (before any kernel module is
    imported); returns it, or ``None`` when the user set ``NUMBA_CACHE_DIR`` or no cache
    directory can be made (numba then keeps its own default, ``__pycache__``)."""
    import numba

    chosen = os.environ.get("NUMBA_CACHE_DIR")
    ours = chosen is not None and chosen == os.environ.get(_MARK)
    if (chosen and not ours) or (not chosen and numba.config.CACHE_DIR):
        return None
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "tfloc" / "numba"
    here = base / source_hash(_roots(), PRESENTATION)
    try:
        here.mkdir(parents=True, exist_ok=True)
        os.utime(here)
    except OSError:
        if ours:  # not a parent's directory of perhaps another source version
            del os.environ["NUMBA_CACHE_DIR"], os.environ[_MARK]
            numba.config.CACHE_DIR = ""
        return None
    numba.config.CACHE_DIR = str(here)
    os.environ["NUMBA_CACHE_DIR"] = os.environ[_MARK] = str(here)  # kept when numba re-reads
    _prune(base, here)
    return str(here)


def _prune(base: Path, here: Path) -> None:
    """Remove the caches of all but the ``KEEP`` most recently used other versions (best effort:
    another process may be using or removing one)."""
    try:
        others = sorted((d for d in base.iterdir() if d.is_dir() and d != here),
                        key=lambda d: d.stat().st_mtime, reverse=True)
    except OSError:
        return
    for old in others[KEEP:]:
        shutil.rmtree(old, ignore_errors=True)
