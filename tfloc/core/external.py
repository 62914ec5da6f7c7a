"""External localizers: a localizer that runs as its own program (any language), the protocol pure.

Such a program cannot be stepped scan by scan from Python: it takes the whole sequence in its own
formats, runs, and writes its poses. A tracker that wraps one declares ``run_batch`` (see
:class:`BatchTracker`) instead of answering ``step``; the tracking loop
(:func:`tfloc.harness.track.track`) detects it (:func:`is_batch_tracker`) and writes the same rows
as for any tracker: ``init_*`` the last answer composed with the odometry increment, ``est_*`` the
program's pose of that scan. The harness side (writing files, the subprocess, its CPU time) is
:mod:`tfloc.baselines._external`.

* :class:`ExternalProgram`: what runs (executable, the Debian package that ships it, its version)
  and with what configuration (the configuration file's text): :meth:`ExternalProgram.identity`
  goes into a run's fingerprint, so a changed configuration file or program version shows.
* :class:`BatchAnswer`: the program's poses, one per scan, its CPU time and where the per-scan
  times came from (:data:`CPU_EVEN`: the child's total split evenly; :data:`CPU_OWN_LOG`: the
  program's own per-scan times, scaled to the child's total).

Units: metres, radians, seconds.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from .laser import LaserSpec
from .map import Map
from .pose import Pose

#: ``BatchAnswer.cpu_from``: the child process's CPU time split evenly over the scans
CPU_EVEN = "even"
#: ``BatchAnswer.cpu_from``: the program's own per-scan times, scaled to sum to the child's CPU time
CPU_OWN_LOG = "own-log"


@dataclass(frozen=True)
class ExternalProgram:
    """An external localizer: ``executable`` (looked up on ``PATH``), ``package`` the Debian
    package to install when it is missing, ``version`` as the program reports it, ``config_name``
    and ``config_text`` its configuration file (the exact text the program is given, before the
    per-run paths and start pose are filled in)."""

    executable: str
    package: str
    version: str
    config_name: str
    config_text: str = field(repr=False)

    def identity(self) -> dict[str, str]:
        """What a run's fingerprint records of the program (JSON-serialisable)."""
        return {"executable": self.executable, "package": self.package, "version": self.version,
                "config": self.config_name,
                "config_sha256": hashlib.sha256(self.config_text.encode()).hexdigest()}


@dataclass(frozen=True)
class BatchAnswer:
    """A program's answer to a whole sequence: ``poses`` ``(N, 3)`` (x, y, theta; one per scan, in
    order), ``cpu_s`` the child process's CPU time (user + system, seconds) and ``wall_s`` its wall
    time, ``cpu_per_scan_s`` ``(N,)`` and ``cpu_from`` how they were split, ``info`` one dict per
    scan (e.g. the program's own confidence)."""

    poses: np.ndarray
    cpu_s: float
    wall_s: float
    cpu_per_scan_s: np.ndarray
    cpu_from: str
    info: tuple[dict, ...] = ()


def split_cpu(total_s: float, n: int, own_s: np.ndarray | None = None) -> tuple[np.ndarray, str]:
    """``total_s`` over ``n`` scans: in proportion to the program's own per-scan times ``own_s``
    where it gives ``n`` finite non-negative ones with a positive sum (:data:`CPU_OWN_LOG`), else
    evenly (:data:`CPU_EVEN`)."""
    if n <= 0:
        return np.zeros(0), CPU_EVEN
    if own_s is not None:
        own = np.asarray(own_s, dtype=float)
        if own.shape == (n,) and np.all(np.isfinite(own)) and np.all(own >= 0) and own.sum() > 0:
            return total_s * own / own.sum(), CPU_OWN_LOG
    return np.full(n, total_s / n), CPU_EVEN


@runtime_checkable
class BatchTracker(Protocol):
    """A tracker that answers a whole sequence at once (an external program)."""

    name: str

    def run_batch(self, map: Map, laser: LaserSpec, ranges: list[np.ndarray], stamps: np.ndarray,
                  odometry: np.ndarray, start: Pose) -> BatchAnswer:
        """The poses of the scans ``ranges`` (metres, one array per scan) taken at ``stamps``
        (seconds) with the wheel odometry ``odometry`` ``(N, 3)`` (the odometry frame's poses),
        the robot starting at ``start`` (world frame) on ``map``."""
        ...


def is_batch_tracker(obj: object) -> bool:
    """Whether ``obj`` answers whole sequences (``run_batch``) rather than scan by scan."""
    return callable(getattr(obj, "run_batch", None))
