"""Code identity: what answers a run's tasks, so that a rerun never reuses rows made by other code.

* tfloc's own code that decides a row (every module of the package and of ``tfloc.baselines``,
  and ``presets.toml``; the presentation layers ``report``, ``cli`` and ``site`` left out: they
  draw rows, they do not make them) is one SHA-256 over its files' paths and bytes
  (:func:`tfloc_code`), whatever the install (editable or not);
* a plugin matcher (a ``module:Class`` or a third party's entry point) is its distribution's name
  and version, where it has one, and a SHA-256 of its source: the module's file, or every
  ``.py`` file of its top-level package (:func:`matcher_code`).

The run's fingerprint records both (:mod:`tfloc.harness.fingerprint`); a change to either stops a
resume with one line naming it (``byo_probe:Probe: source changed``).
"""

from __future__ import annotations

import hashlib
import importlib
import re
import subprocess
import sys
from functools import cache
from importlib import metadata
from pathlib import Path
from typing import Any

from tfloc._kernel_cache import PRESENTATION  # the parts that draw rows, not make them


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


def _package_dir(module: str) -> Path:
    return Path(importlib.import_module(module).__file__).resolve().parent


def tfloc_files() -> dict[str, Path]:
    """The files of tfloc's answering code by package path (``tfloc/paper/corners.py``,
    ``tfloc/baselines/karto.py``, ``tfloc/presets.toml``)."""
    out: dict[str, Path] = {}
    for module in ("tfloc", "tfloc.baselines"):
        root = _package_dir(module)
        prefix = module.replace(".", "/")
        for f in root.rglob("*"):
            rel = f.relative_to(root)
            if f.suffix not in (".py", ".toml") or "__pycache__" in rel.parts or not f.is_file():
                continue
            if module == "tfloc" and rel.parts[0] in (*PRESENTATION, "baselines"):
                continue
            out[f"{prefix}/{rel.as_posix()}"] = f
    return out


@cache
def tfloc_code() -> dict[str, Any]:
    """tfloc's version and the SHA-256 of its answering code (computed once per process)."""
    try:
        version = metadata.version("tfloc")
    except metadata.PackageNotFoundError:
        version = None
    return {"version": version, "source": _hash_files(tfloc_files())}


def _distribution(top: str) -> tuple[str | None, str | None]:
    names = metadata.packages_distributions().get(top) or []
    for name in names:
        try:
            return name, metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return None, None


def module_source(module: str) -> str:
    """SHA-256 of a module's source: every ``.py`` file of its top-level package, or its file."""
    top = importlib.import_module(module.split(".")[0])
    path = Path(getattr(top, "__file__", "") or "")
    if getattr(top, "__path__", None) and path.name == "__init__.py":
        root = path.resolve().parent
        files = {f.relative_to(root).as_posix(): f for f in root.rglob("*.py") if "__pycache__" not in f.parts}
    else:
        mod = sys.modules[module]
        files = {Path(mod.__file__).name: Path(mod.__file__)} if getattr(mod, "__file__", None) else {}
    return _hash_files(files)


def matcher_code(factory: Any) -> dict[str, Any]:
    """What answers for a matcher built by ``factory``: ``{"code": "tfloc"}`` for tfloc's own
    (the run's tfloc source covers it), else the plugin's distribution, version and source hash."""
    module = getattr(factory, "__module__", "") or ""
    if module == "tfloc" or module.startswith("tfloc."):
        return {"code": "tfloc"}
    dist, version = _distribution(module.split(".")[0])
    return {"code": "plugin", "module": module, "distribution": dist, "version": version,
            "source": module_source(module)}


def git_state() -> dict:
    """``{"commit", "dirty"}`` of the checkout tfloc runs from: ``dirty`` when its answering code
    (``tfloc/``, ``baselines/``, ``pyproject.toml``, ``requirements.lock``) differs from the
    commit, untracked files included; results and documents do not count (``None`` each where
    git cannot say, e.g. an installed wheel)."""
    root = _package_dir("tfloc").parent
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
