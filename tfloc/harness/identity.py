"""Code identity: which code decides a matcher's rows, so that a rerun never reuses rows made by
other code, and an edit elsewhere leaves them current.

A matcher's rows are decided by its own code and what that code imports, and by the harness code
that turns its answers into rows (the scan task and the tracking loop, with the dataset reading
and the row codec they import: :data:`ROW_CODE`). So the identity of a tfloc matcher is the
SHA-256 of the files of that import closure (:func:`code_identity`, over
:mod:`tfloc.harness.imports`' static graph): an edit to a module none of them imports
(``datasets/spacing.py``, the report, the site) changes no matcher's identity; an edit to
``tfplus/cost.py`` changes those of ``tf-plus``, ``tf-plus-track`` and every matcher that imports
it, and no other.

* a tfloc matcher records ``{"code": "tfloc", "source": <its closure's hash>}``
  (:func:`matcher_code`);
* a plugin matcher (a ``module:Class`` or a third party's entry point) records its distribution's
  name and version, where it has one, and a SHA-256 of its source (the module's file, or every
  ``.py`` file of its top-level package), beside the hash of tfloc's row code
  (``"source"`` is then the plugin's, ``"rows"`` tfloc's);
* a run's fingerprint also records every file of those closures with its hash
  (:func:`files_of`), so a difference can name the files that changed.

Tables derived from rows (headline, report, verdict, the site) carry the identity of the code
that derives them the same way (:func:`derived_code`): re-made from the rows when it changes,
never by re-running matchers.
"""

from __future__ import annotations

import hashlib
import importlib
import re
import subprocess
import sys
from collections.abc import Iterable
from functools import cache
from importlib import metadata
from pathlib import Path
from typing import Any

from .imports import closure, combined, file_hashes

#: the harness code that turns a matcher's answers into rows: the scan task, the tracking loop
#: (both import the workspace, the dataset reader and the outcome rule) and the rows' codec
ROW_CODE = ("tfloc.harness.task", "tfloc.harness.track", "tfloc.io.estimates")


def tfloc_version() -> str | None:
    """tfloc's installed version (recorded; it decides no row)."""
    try:
        return metadata.version("tfloc")
    except metadata.PackageNotFoundError:
        return None


def is_tfloc_module(module: str) -> bool:
    return module == "tfloc" or module.startswith("tfloc.")


def closure_files(roots: Iterable[str]) -> dict[str, str]:
    """Package path → SHA-256 of every file of the import closure of the modules ``roots``."""
    return file_hashes(closure(roots))


def code_identity(roots: Iterable[str]) -> str:
    """The identity of the code the modules ``roots`` run: one SHA-256 over their import
    closure's files (paths and contents)."""
    return combined(closure_files(roots))


def _row_roots(module: str, row_code: tuple[str, ...]) -> list[str]:
    return [module, *row_code] if is_tfloc_module(module) else list(row_code)


def files_of(factory: Any, row_code: tuple[str, ...] = ROW_CODE) -> dict[str, str]:
    """The files (package path → SHA-256) that decide the rows of a matcher built by ``factory``:
    its module's closure (a tfloc matcher) and the row code's."""
    return closure_files(_row_roots(getattr(factory, "__module__", "") or "", row_code))


def _distribution(top: str) -> tuple[str | None, str | None]:
    names = metadata.packages_distributions().get(top) or []
    for name in names:
        try:
            return name, metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return None, None


def _hash_files(files: dict[str, Path]) -> str:
    """SHA-256 over ``name → file`` in name order (each name and its bytes)."""
    h = hashlib.sha256()
    for name in sorted(files):
        h.update(name.encode() + b"\0")
        try:
            h.update(files[name].read_bytes())
        except OSError:
            h.update(b"(unreadable)")
        h.update(b"\0")
    return h.hexdigest()


def module_source(module: str) -> str:
    """SHA-256 of a plugin module's source: every ``.py`` file of its top-level package, or its
    file."""
    top = importlib.import_module(module.split(".")[0])
    path = Path(getattr(top, "__file__", "") or "")
    if getattr(top, "__path__", None) and path.name == "__init__.py":
        root = path.resolve().parent
        files = {f.relative_to(root).as_posix(): f for f in root.rglob("*.py") if "__pycache__" not in f.parts}
    else:
        mod = sys.modules[module]
        files = {Path(mod.__file__).name: Path(mod.__file__)} if getattr(mod, "__file__", None) else {}
    return _hash_files(files)


def matcher_code(factory: Any, row_code: tuple[str, ...] = ROW_CODE) -> dict[str, Any]:
    """What answers for a matcher built by ``factory`` (module notes): ``{"code": "tfloc",
    "source"}`` for tfloc's own, else the plugin's distribution, version and source with
    tfloc's row code (``rows``)."""
    module = getattr(factory, "__module__", "") or ""
    if is_tfloc_module(module):
        return {"code": "tfloc", "source": code_identity(_row_roots(module, row_code))}
    dist, version = _distribution(module.split(".")[0])
    return {"code": "plugin", "module": module, "distribution": dist, "version": version,
            "source": module_source(module), "rows": code_identity(row_code)}


def stale_matchers(fingerprint: Any) -> list[str] | None:
    """The labels of a recorded fingerprint whose rows this checkout's code would not make (their
    code identity differs, or their matcher is gone); ``None`` where the fingerprint records no
    per-matcher identity."""
    from tfloc.core.matcher import factory_of
    from tfloc.errors import TflocError

    recorded = (fingerprint or {}).get("matchers") if isinstance(fingerprint, dict) else None
    if not recorded or not all(isinstance(r, dict) and r.get("source") for r in recorded.values()):
        return None
    out = []
    for label, r in recorded.items():
        try:
            now = matcher_code(factory_of(r["name"]))
        except TflocError:
            now = {}
        if any(now.get(k) != r.get(k) for k in ("code", "source", "rows")):
            out.append(label)
    return out


@cache
def derived_code(*roots: str) -> str:
    """The identity of the code that derives a table from rows (the modules ``roots`` and their
    closure), computed once per process."""
    return code_identity(roots)


def git_state() -> dict:
    """``{"commit", "dirty"}`` of the checkout tfloc runs from: ``dirty`` when its code
    (``tfloc/``, ``baselines/``, ``pyproject.toml``, ``requirements.lock``) differs from the
    commit, untracked files included; results and documents do not count (``None`` each where
    git cannot say, e.g. an installed wheel)."""
    root = Path(importlib.import_module("tfloc").__file__).resolve().parent.parent
    try:
        git = ["git", "-C", str(root)]
        commit = subprocess.run([*git, "rev-parse", "HEAD"], capture_output=True, text=True,
                                timeout=10).stdout.strip() or None
        dirty = None
        if commit:
            out = subprocess.run([*git, "status", "--porcelain", "--untracked-files=all", "--",
                                  "tfloc", "baselines", "pyproject.toml", "requirements.lock"],
                                 capture_output=True, text=True, timeout=10).stdout
            dirty = bool(out.strip())
    except (OSError, subprocess.SubprocessError):
        commit, dirty = None, None
    return {"commit": commit, "dirty": dirty}


def recorded_packages() -> tuple[str, ...]:
    """The distributions whose versions ``run.json`` records: tfloc and what its installed
    metadata requires (its dependencies and every extra but the development tools'), in the
    order declared: a new baseline's library is recorded once its extra names it."""
    try:
        reqs = metadata.requires("tfloc") or []
    except metadata.PackageNotFoundError:
        reqs = []
    names = [re.split(r"[\s;<>=!~\[(]", r, maxsplit=1)[0] for r in reqs
             if ";" not in r or 'extra == "dev"' not in r]
    return tuple(dict.fromkeys(["tfloc", *names]))
