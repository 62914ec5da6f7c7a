"""Running an external localizer (:mod:`tfloc.core.external`): the program found on ``PATH``, run
as a child process, its CPU time measured as the child's own.

* :func:`find_program` — the executable's path, or :class:`ExternalProgramError` naming the
  Debian package to install (``apt-get install mrpt-apps``); a run leaves such a matcher out with
  that line (it is a :class:`~tfloc.errors.LibraryMissingError`).
* :func:`run_program` — one run: ``argv`` in ``cwd`` with stdin closed, stdout and stderr to
  files; the child's CPU time (user + system) from ``os.wait4``'s resource usage of that child
  alone (not this process's, not other children's). A non-zero exit raises
  :class:`ExternalProgramError` with the program's last stderr line (or stdout's, where it logs
  there).
* :func:`read_table` — a whitespace table the program wrote, checked for its row count.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tfloc.errors import LibraryMissingError, TflocError


class ExternalProgramError(TflocError):
    """An external program failed, or its output is not what the protocol expects."""


class ProgramMissingError(LibraryMissingError):
    """An external program is not installed (the message names the package to install)."""


def find_program(executable: str, package: str) -> str:
    """The path of ``executable`` on ``PATH``; :class:`ProgramMissingError` names ``package``."""
    path = shutil.which(executable)
    if path is None:
        raise ProgramMissingError(f"{executable} not found on PATH (Debian: apt-get install {package})")
    return path


@dataclass(frozen=True)
class ProgramRun:
    """One finished child process: its stdout and stderr files, CPU (user + system) and wall time
    (seconds)."""

    stdout: Path
    stderr: Path
    cpu_s: float
    wall_s: float


def _last_line(*paths: Path) -> str:
    for p in paths:
        try:
            lines = [ln.strip() for ln in p.read_text(errors="replace").splitlines() if ln.strip()]
        except OSError:
            continue
        if lines:
            return lines[-1][:300]
    return "(no output)"


def run_program(argv: list[str], cwd: Path, *, timeout_s: float | None = None, tag: str = "run") -> ProgramRun:
    """Run ``argv`` in ``cwd`` (stdout/stderr to ``cwd/<tag>.stdout|.stderr``) and wait for it;
    raise :class:`ExternalProgramError` (one line) on a non-zero exit, a signal or a timeout."""
    cwd = Path(cwd)
    out, err = cwd / f"{tag}.stdout", cwd / f"{tag}.stderr"
    name = Path(argv[0]).name
    t0 = time.perf_counter()
    with out.open("wb") as fo, err.open("wb") as fe:
        try:
            proc = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=fo, stderr=fe)
        except OSError as exc:
            raise ExternalProgramError(f"{name}: cannot start ({exc.strerror or exc})") from None
        deadline = None if timeout_s is None else t0 + timeout_s
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG if deadline else 0)
            if pid:
                break
            if time.perf_counter() > deadline:
                proc.kill()
                os.wait4(proc.pid, 0)
                raise ExternalProgramError(f"{name}: timed out after {timeout_s:g} s")
            time.sleep(0.05)
        proc.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        how = f"exit status {proc.returncode}" if proc.returncode > 0 else f"signal {-proc.returncode}"
        raise ExternalProgramError(f"{name} failed ({how}): {_last_line(err, out)}")
    return ProgramRun(out, err, usage.ru_utime + usage.ru_stime, wall)


def read_table(path: Path, rows: int, cols: int, what: str) -> np.ndarray:
    """``path`` as a ``(rows, cols)`` float table; :class:`ExternalProgramError` (one line naming
    the file) when it is missing or has another shape."""
    try:
        a = np.loadtxt(path, ndmin=2, comments=("%", "#"))
    except (OSError, ValueError) as exc:
        raise ExternalProgramError(f"{path}: cannot read {what} ({str(exc).splitlines()[0][:120]})") from None
    if a.shape != (rows, cols):
        raise ExternalProgramError(f"{path}: {what}: {a.shape[0]} rows of {a.shape[1] if a.size else 0} "
                                   f"values, expected {rows} rows of {cols}")
    return a
