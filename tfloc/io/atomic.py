"""Writing a file so that a crash or a kill leaves the old file or the new one, never a mix: a
temporary file beside it, flushed and fsynced, renamed over it, and the directory fsynced."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

from tfloc.errors import ResultsError


def sync_dir(directory: Path) -> None:
    """fsync a directory, so that a rename in it survives a crash."""
    fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def replace_atomically(path: Path, write: Callable[[TextIO], None], what: str = "cannot write") -> None:
    """``write(fh)`` into ``path`` atomically (module notes); an OS error is a one-line
    :class:`ResultsError` naming the file (``what``: how to say it failed)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        with tmp.open("w", newline="") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
        sync_dir(path.parent)
    except OSError as exc:
        raise ResultsError(f"{path}: {what} ({exc.strerror or exc})") from None
