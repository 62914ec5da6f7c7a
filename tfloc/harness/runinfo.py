"""``run.json``: a run's configuration, package versions, git commit and machine."""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from .config import RunConfig

PACKAGES = ("tfloc", "numpy", "scipy", "shapely", "pandas", "numba", "pebble", "matplotlib",
            "open3d", "kiss-icp", "opencv-python-headless")


def package_versions() -> dict[str, str | None]:
    out = {}
    for p in PACKAGES:
        try:
            out[p] = version(p)
        except PackageNotFoundError:
            out[p] = None
    return out


def git_commit() -> str | None:
    """The current commit (with ``-dirty`` if the tree has changes), or None outside git."""
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                             timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return sha + ("-dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return None


def machine() -> dict:
    return {"platform": platform.platform(), "processor": platform.processor() or platform.machine(),
            "cpu_count": os.cpu_count(), "python": sys.version.split()[0]}


def write_run_json(path: Path, cfg: RunConfig, **extra) -> None:
    """Write (or update) ``run.json``; earlier starts are kept in ``history``."""
    old = json.loads(path.read_text()) if path.exists() else {}
    now = datetime.now(UTC).isoformat(timespec="seconds")
    history = old.get("history", [])
    if not extra.get("finished"):
        history.append({"started": now, "commit": git_commit()})
    doc = {"config": cfg.to_dict(), "versions": package_versions(), "git_commit": git_commit(),
           "machine": machine(), "threads_per_worker": max(1, 2 // cfg.jobs),
           "updated": now, "history": history, **extra}
    path.write_text(json.dumps(doc, indent=2) + "\n")
