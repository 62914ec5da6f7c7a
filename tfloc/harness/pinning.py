"""One process pinned to a core, matchers interleaved: the conditions of every side-by-side timing.

:func:`pinned` runs a block pinned to the given cores (``os.sched_setaffinity``; default: the
last core this process may run on) with every library on one thread
(:func:`tfloc.harness.threads.limit_threads`), and restores the affinity after; :func:`rotated`
is the order of the matchers on scan ``i``: rotated by ``i``, so that slow drifts of the machine
(load, frequency) hit every matcher alike. The timing pass (:mod:`tfloc.harness.timing`) and the
scaling study (:mod:`tfloc.harness.scaling`) measure under both.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import TypeVar

from tfloc.errors import ConfigError

from .threads import limit_threads

T = TypeVar("T")


def pin(cores: Sequence[int]) -> list[int]:
    """Pin this process to ``cores`` (where the OS allows); returns the cores it now runs on."""
    if hasattr(os, "sched_setaffinity"):
        try:
            os.sched_setaffinity(0, set(cores))
        except OSError as exc:
            raise ConfigError(f"cannot pin to cores {list(cores)}: {exc}") from None
        return sorted(os.sched_getaffinity(0))
    return []


@contextmanager
def pinned(cores: Sequence[int] | None = None) -> Iterator[list[int]]:
    """The block runs pinned to ``cores`` (default: the last core this process may run on), every
    library on one thread; yields the cores it runs on, and restores the affinity after."""
    before = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    try:
        now = pin(before[-1:] if cores is None else cores)
        limit_threads(1)
        yield now
    finally:
        if before:
            os.sched_setaffinity(0, before)


def rotated(items: Sequence[T], i: int) -> list[tuple[int, T]]:
    """Scan ``i``'s order of ``items`` (matchers): rotated by ``i``, each with its position, so
    that slow drifts of the machine hit every matcher alike."""
    k = len(items)
    return [(pos, items[(i + pos) % k]) for pos in range(k)]
