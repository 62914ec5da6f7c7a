"""Cartographer's filters of a 2D scan's returns before matching (``sensor/internal/voxel_filter.cc``,
``local_trajectory_builder_2d.cc``), in their order:

1. **Range**: returns farther than ``max_range`` (``TRAJECTORY_BUILDER_2D.max_range`` 30 m) become
   misses, which the matchers never read; returns nearer than ``min_range`` (0 m) are dropped.
2. **Voxel filter** of ``voxel_filter_size`` (0.025 m): one return per voxel.
3. **Adaptive voxel filter** (``adaptive_voxel_filter``: ``max_length`` 0.5 m, ``min_num_points``
   200, ``max_range`` 50 m): a scan of at most ``min_num_points`` returns is kept whole; else
   the voxel filter at ``max_length`` if that keeps enough, else the edge halved until it keeps
   enough and then bisected to within 10 %.

Cartographer's voxel filter is randomized: each voxel keeps one of its points by reservoir
sampling, with a ``std::minstd_rand0`` generator made anew (default seed 1) for every call and
``std::uniform_int_distribution<>(1, count)``. Both are reproduced as libstdc++ implements them
(the Lehmer generator ×16807 mod 2³¹−1; the distribution's rejection "downscaling", since the
generator's range is not a power of two), so the same points are kept. A voxel is the point's
coordinates divided by the edge, rounded (``RoundToInt``: half away from zero). Points are the
scan's returns in the robot frame, metres, in beam order.
"""

from __future__ import annotations

import numpy as np

_MINSTD_A, _MINSTD_M = 16807, 2147483647


class _MinstdRand0:
    """``std::minstd_rand0`` with its default seed, and libstdc++'s ``uniform_int_distribution``."""

    def __init__(self) -> None:
        self.state = 1

    def __call__(self) -> int:
        self.state = (self.state * _MINSTD_A) % _MINSTD_M
        return self.state

    def uniform(self, lo: int, hi: int) -> int:
        """``std::uniform_int_distribution<>(lo, hi)(*this)`` as libstdc++ draws it."""
        urng_range = (_MINSTD_M - 1) - 1  # max() − min() of the generator
        span = hi - lo
        if span == 0:
            return lo
        extended = span + 1
        scaling = urng_range // extended
        past = extended * scaling
        while True:
            ret = self() - 1
            if ret < past:
                return lo + ret // scaling


def _round_half_away(v: np.ndarray) -> np.ndarray:
    v = v.astype(np.float64)
    return (np.sign(v) * np.floor(np.abs(v) + 0.5)).astype(np.int64)


def voxel_filter(points: np.ndarray, edge: float) -> np.ndarray:
    """``VoxelFilter(points, edge)``: the indices of the points kept, in order (one per voxel,
    chosen by Cartographer's reservoir sampling)."""
    if len(points) == 0:
        return np.zeros(0, dtype=np.int64)
    keys = _round_half_away(points.astype(np.float32) / np.float32(edge))  # float, as Cartographer
    rng = _MinstdRand0()
    chosen: dict[tuple[int, int], list[int]] = {}
    for n, (a, b) in enumerate(keys.tolist()):
        slot = chosen.setdefault((a, b), [0, n])
        slot[0] += 1
        if slot[0] > 1 and rng.uniform(1, slot[0]) == slot[0]:
            slot[1] = n
    return np.sort(np.fromiter((s[1] for s in chosen.values()), dtype=np.int64))


def adaptive_voxel_filter(points: np.ndarray, max_length: float, min_num_points: int,
                          max_range: float) -> np.ndarray:
    """``AdaptiveVoxelFilter``: the indices of the points kept (module notes, step 3)."""
    near = np.flatnonzero(np.hypot(points[:, 0], points[:, 1]) <= max_range)
    cloud = points[near]
    if len(cloud) <= min_num_points:
        return near
    kept = voxel_filter(cloud, max_length)
    if len(kept) >= min_num_points:
        return near[kept]
    f32, half = np.float32, np.float32(2.0)
    high = f32(max_length)
    while high > 1e-2 * max_length:
        low = high / half
        kept = voxel_filter(cloud, low)
        if len(kept) >= min_num_points:
            while (high - low) / low > f32(1e-1):
                mid = (low + high) / half
                candidate = voxel_filter(cloud, mid)
                if len(candidate) >= min_num_points:
                    low, kept = mid, candidate
                else:
                    high = mid
            return near[kept]
        high = high / half
    return near[kept]


def matched_points(points: np.ndarray, *, min_range: float, max_range: float, voxel_size: float,
                   max_length: float, min_num_points: int, adaptive_max_range: float) -> np.ndarray:
    """The returns Cartographer's local matchers use, ``(M, 2)`` robot frame (module notes)."""
    r = np.hypot(points[:, 0], points[:, 1])
    returns = points[(r >= min_range) & (r <= max_range)]
    returns = returns[voxel_filter(returns, voxel_size)]
    return returns[adaptive_voxel_filter(returns, max_length, min_num_points, adaptive_max_range)]
