"""The memory a block of code keeps and peaks at: resident set size, not what tracemalloc sees.

:class:`MemoryProbe` measures retained memory (RSS after minus before, each after a garbage
collection and glibc's ``malloc_trim(0)``, so that memory freed earlier and kept by the allocator
neither hides nor inflates what the block keeps) and the peak above the memory before (Linux:
``VmHWM``, reset through ``/proc/self/clear_refs``). Both count what numba, open3d and other
native libraries allocate. In MB (2²⁰ bytes). The scaling study measures every preparation with it.
"""

from __future__ import annotations

import gc
import math
from pathlib import Path


def rss_mb() -> float:
    """This process's resident memory (MB, psutil) after a garbage collection and
    ``malloc_trim(0)`` (glibc returns its free heap pages to the OS)."""
    import psutil

    gc.collect()
    try:
        import ctypes

        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass
    return psutil.Process().memory_info().rss / 2**20


def reset_peak() -> bool:
    """Reset this process's peak resident memory (Linux: ``/proc/self/clear_refs`` ← 5)."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return True
    except OSError:
        return False


def peak_mb() -> float:
    """This process's peak resident memory since :func:`reset_peak` (MB; VmHWM), NaN if unknown."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return math.nan


class MemoryProbe:
    """Retained and peak resident memory (MB) of a block: ``with MemoryProbe() as m: ...``, then
    ``m.retained_mb`` (RSS after minus before) and ``m.peak_mb`` (the peak above the memory
    before; NaN where the OS cannot tell)."""

    def __enter__(self) -> MemoryProbe:
        self._r0 = rss_mb()
        self._peak = reset_peak()
        return self

    def __exit__(self, *exc: object) -> None:
        self.peak_mb = peak_mb() - self._r0 if self._peak else math.nan
        self.retained_mb = rss_mb() - self._r0
