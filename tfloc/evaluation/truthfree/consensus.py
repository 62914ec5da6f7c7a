"""Agreement with the other trackers: the pose independent methods agree on, the tracker left out.

At each scan, two answers *agree* when they are within the tracked thresholds of each other
(``agree_m``, ``agree_rad``). For tracker *i* the witnesses are the trackers of every other
method (:func:`tfloc.core.traits.method_of`; a method's several configurations are one witness,
a tracker that never looks at the map none). Around each witness *j* gather the witnesses that
agree with it and count their distinct methods; the largest such group is the consensus when it
has at least ``min_methods`` methods and every witness at that size agrees with the others at
that size (two rival groups of one size are no consensus). Tracker *i* agrees where its answer
agrees with a witness of the consensus. A consensus of wrong answers is possible (every method
fooled alike); the verdict's validation on recordings with truth measures how often.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


def close(poses: np.ndarray, agree_m: float, agree_rad: float) -> np.ndarray:
    """``(M, M, N)`` whether answers ``poses`` ``(M, N, 3)`` of two trackers agree at each scan
    (non-finite answers agree with nothing)."""
    p = np.asarray(poses, dtype=float)
    dx = p[:, None, :, 0] - p[None, :, :, 0]
    dy = p[:, None, :, 1] - p[None, :, :, 1]
    da = np.abs((p[:, None, :, 2] - p[None, :, :, 2] + math.pi) % (2 * math.pi) - math.pi)
    return (np.hypot(dx, dy) <= agree_m) & (da <= agree_rad)


@nb.njit(cache=True)
def _consensus(c: np.ndarray, method: np.ndarray, n_methods: int, min_methods: int):  # noqa: ANN202
    m, _, n = c.shape
    agree = np.zeros((m, n), dtype=np.bool_)
    known = np.zeros((m, n), dtype=np.bool_)
    support = np.zeros((m, n), dtype=np.int64)
    seen = np.zeros(n_methods, dtype=np.bool_)
    size = np.zeros(m, dtype=np.int64)
    for k in range(n):
        for i in range(m):
            for j in range(m):
                size[j] = 0
                if method[j] < 0 or method[j] == method[i]:
                    continue
                seen[:] = False
                for o in range(m):
                    if method[o] >= 0 and method[o] != method[i] and c[j, o, k] and not seen[method[o]]:
                        seen[method[o]] = True
                        size[j] += 1
            best = 0
            for j in range(m):
                best = max(best, size[j])
            support[i, k] = best
            if best < min_methods:
                continue
            unique = True
            for a in range(m):
                for b in range(m):
                    if size[a] == best and size[b] == best and not c[a, b, k]:
                        unique = False
            if not unique:
                continue
            known[i, k] = True
            for j in range(m):
                if size[j] == best and c[i, j, k]:
                    agree[i, k] = True
    return agree, known, support


def consensus(poses: np.ndarray, methods: list[str | None], agree_m: float, agree_rad: float,
              min_methods: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per tracker and scan (``(M, N)`` each): whether it agrees with the consensus of the others,
    whether there is one, and how many methods the largest group of others holds (module notes);
    ``poses`` ``(M, N, 3)``, ``methods`` per tracker (``None``: no witness)."""
    names = sorted({m for m in methods if m is not None})
    ids = np.array([names.index(m) if m is not None else -1 for m in methods], dtype=np.int64)
    return _consensus(close(poses, agree_m, agree_rad), ids, max(len(names), 1), int(min_methods))
