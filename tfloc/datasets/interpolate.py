"""Poses at given times from a timed pose stream: linear in x and y, shortest arc in heading."""

from __future__ import annotations

import math

import numpy as np

from tfloc.core.pose import angdiff, wrap_angle


def interpolate_poses(stamps: np.ndarray, poses: np.ndarray, query: np.ndarray,
                      max_gap: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
    """The poses ``(M, 3)`` (m, m, rad) at times ``query`` ``(M,)`` (s), and which are covered.

    ``stamps`` ``(N,)`` must be strictly increasing and ``poses`` ``(N, 3)`` aligned with them.
    A query time is covered if it lies in ``[stamps[0], stamps[-1]]`` and the two samples that
    bracket it are at most ``max_gap`` seconds apart (a query equal to a sample is always
    covered). Between two samples x and y are interpolated linearly and the heading along the
    shorter arc; uncovered rows are NaN."""
    t = np.asarray(stamps, dtype=float)
    p = np.asarray(poses, dtype=float).reshape(-1, 3)
    q = np.asarray(query, dtype=float).reshape(-1)
    out = np.full((q.size, 3), np.nan)
    if t.size == 0:
        return out, np.zeros(q.size, dtype=bool)
    hi = np.clip(np.searchsorted(t, q, side="left"), 0, t.size - 1)
    lo = np.clip(hi - 1, 0, t.size - 1)
    exact = t[hi] == q
    lo = np.where(exact, hi, lo)
    inside = (q >= t[0]) & (q <= t[-1])
    covered = inside & (exact | (t[hi] - t[lo] <= max_gap))
    span = t[hi] - t[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(span > 0, (q - t[lo]) / span, 0.0)[covered]
    a, b = p[lo[covered]], p[hi[covered]]
    out[covered, :2] = a[:, :2] + w[:, None] * (b[:, :2] - a[:, :2])
    out[covered, 2] = wrap_angle(a[:, 2] + w * angdiff(b[:, 2], a[:, 2]))
    return out, covered
