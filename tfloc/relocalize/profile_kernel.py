"""Compiled kernels of the range profile (:mod:`tfloc.relocalize.profile`; numba, one core): the
median of each sector's beams, and the robust profile distance of a query to every index entry
(a brute-force pass over the index, as the signature's matrix-vector product)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def sector_medians(values: np.ndarray, starts: np.ndarray, stops: np.ndarray) -> np.ndarray:
    """Median ``(N, S)`` (float32) of the finite ``values[i, starts[j]:stops[j]]`` of ``(N, B)``
    rows; NaN where a slice holds no finite value."""
    n, s = values.shape[0], starts.shape[0]
    out = np.empty((n, s), dtype=np.float32)
    buf = np.empty(values.shape[1])
    for i in range(n):
        for j in range(s):
            k = 0
            for b in range(starts[j], stops[j]):
                v = values[i, b]
                if v == v:
                    buf[k] = v
                    k += 1
            out[i, j] = np.median(buf[:k]) if k > 0 else np.nan
    return out


@njit(cache=True, nogil=True)
def place_distances(base: np.ndarray, profiles: np.ndarray, queries: np.ndarray, truncation: float,
                    weight: float) -> np.ndarray:
    """``base + weight · ρ`` ``(N,)``: ρ is, over the query's shifts ``queries`` ``(K, S)`` (NaN
    = unknown sector), the smallest mean over its known sectors of ``min(|q − p|, truncation)``
    against each entry's profile, ``profiles`` ``(S, N)`` (finite; sector-major, so that each
    sector is one pass over the entries; ``truncation`` where no sector is known)."""
    s, n = profiles.shape
    tau = np.float32(truncation)
    best = np.full(n, tau, dtype=np.float32)
    acc = np.empty(n, dtype=np.float32)
    for k in range(queries.shape[0]):
        acc[:] = 0.0
        count = 0
        for j in range(s):
            q = np.float32(queries[k, j])
            if q != q:
                continue
            count += 1
            row = profiles[j]
            for i in range(n):
                acc[i] += min(abs(q - row[i]), tau)
        if count == 0:
            continue
        c = np.float32(count)
        for i in range(n):
            r = acc[i] / c
            if r < best[i]:
                best[i] = r
    out = np.empty(n)
    for i in range(n):
        out[i] = base[i] + weight * best[i]
    return out
