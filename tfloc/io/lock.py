"""``requirements.lock``: the exact versions ``make`` installs (``make lock`` refreshes it), and
how a run's recorded versions differ from them.

The lock lives at the top of a source checkout; an installed tfloc without one has no lock to
compare with (``find_lock`` returns ``None``). Its lines are pip requirements, ``name==version``
with an optional environment marker (uv's universal lock forks a package by Python version):
each marker is evaluated for the Python a run recorded, not the one reading the lock."""

from __future__ import annotations

import re
from pathlib import Path

from packaging.markers import Marker
from packaging.utils import canonicalize_name

from tfloc.errors import ConfigError
from tfloc.io.text import read_text

LOCK_NAME = "requirements.lock"
_PIN = re.compile(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;\\]+)\s*(?:;\s*([^\\]+?))?\s*\\?$")


def find_lock() -> Path | None:
    """The lock of the checkout this tfloc runs from, or ``None`` (an installed copy)."""
    path = Path(__file__).resolve().parents[2] / LOCK_NAME
    return path if path.is_file() else None


def read_lock(path: Path, python: str | None = None) -> dict[str, str]:
    """Canonical package name → locked version for Python ``python`` (``"3.11.7"``; ``None`` or
    anything but a version: markers are not evaluated, the first pin of a name wins).
    A line that is neither a pin, a hash, a comment nor blank is a ``ConfigError`` naming it."""
    env = None
    if isinstance(python, str) and re.fullmatch(r"\d+\.\d+(\.\d+)?", python):
        major_minor = ".".join(python.split(".")[:2])
        env = {"python_version": major_minor, "python_full_version": python}
    out: dict[str, str] = {}
    for i, line in enumerate(read_text(path, ConfigError, "a pip requirements lock").splitlines(), start=1):
        s = line.strip()
        if not s or s.startswith(("#", "--hash")):
            continue
        m = _PIN.match(s)
        if not m:
            raise ConfigError(f"{path}:{i}: not a pinned requirement: {s[:60]!r}")
        name, version, marker = canonicalize_name(m.group(1)), m.group(2), m.group(3)
        if marker and env is not None and not Marker(marker).evaluate(env):
            continue
        out.setdefault(name, version)
    return out


def lock_differences(versions: dict[str, str | None], lock: dict[str, str]) -> dict[str, tuple[str | None, str]]:
    """The recorded ``versions`` (name → version, ``None``: not installed) that are not the
    lock's: name → (recorded, locked). Packages the lock does not hold (tfloc itself) are not
    compared."""
    out = {}
    for name, got in versions.items():
        want = lock.get(canonicalize_name(name))
        if want is not None and got != want:
            out[name] = (got, want)
    return out
