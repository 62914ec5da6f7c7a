"""The frozen submaps of the map and the constraint builder's search of a scan in one
(``constraint_builder_2d.cc``, ``fast_correlative_scan_matcher_2d.cc``).

**Frozen submaps from the map.** In pure localization Cartographer loads the mapping run's
``.pbstream``: its submaps (probability grids written by the range data inserter along the
mapping trajectory) with their optimised poses, frozen. The suite hands a tracker the map, not
the mapping run, so the frozen submaps here are the map's own probability grid
(:func:`._grid.probability_grid`: a cell the map calls occupied 0.9, ``kMaxProbability``, where a
submap's walls saturate; every other cell 0.1) cut into square tiles of ``size_m`` metres,
consecutive tiles overlapping by half (as consecutive submaps share half their scans), each
with its pose at the tile's centre, heading 0. Tiles without an occupied cell are left out.

**Search** (``FastCorrelativeScanMatcher2D``): branch and bound over the precomputation grids
(``bnb-global``'s kernels, :mod:`tfloc.baselines._bnb_kernels`, ``branch_and_bound_depth``
levels), the scan rotated by every heading within ±``angular_window`` (step from its farthest
point) and placed at the initial pose, shifted by whole cells within ±``linear_window``; the
best candidate above ``min_score`` (mean precomputed probability) or none. ``MatchFullSubmap``:
the tile's centre, every heading, shifts covering the tile. Metres, radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from tfloc.baselines._bnb_kernels import angular_step, branch_and_bound, pyramid

from tfloc.core.pose import Pose, wrap_angle
from tfloc.maps.cache import cached

from ._grid import MAX_PROBABILITY, MIN_PROBABILITY, ProbabilityGrid, probability_grid

_SCALE = 255.0 / (MAX_PROBABILITY - MIN_PROBABILITY)  # probability → precomputation value


@dataclass(frozen=True, eq=False)
class FrozenSubmap:
    """One frozen submap: its global ``pose`` (metres, radians), its probability ``grid`` and the
    ``depth`` precomputation grids ``grids`` (uint8, ``pad`` cells of margin)."""

    pose: Pose
    grid: ProbabilityGrid
    grids: np.ndarray
    pad: int


def _build(map_: object, size_m: float, depth: int) -> tuple[FrozenSubmap, ...]:
    full = probability_grid(map_, MAX_PROBABILITY)
    r = full.resolution
    n = max(1, int(round(size_m / r)))
    stride = max(1, n // 2)
    H, W = full.prob.shape
    out = []
    for j0 in range(0, max(H - stride, 1), stride):
        for i0 in range(0, max(W - stride, 1), stride):
            prob = full.prob[j0:j0 + n, i0:i0 + n]
            if not np.any(prob >= MAX_PROBABILITY):
                continue
            origin = (full.origin[0] + i0 * r, full.origin[1] + j0 * r)
            grid = ProbabilityGrid(np.ascontiguousarray(prob), r, origin)
            values = np.rint((prob - MIN_PROBABILITY) * _SCALE).astype(np.uint8)
            centre = Pose(origin[0] + 0.5 * prob.shape[1] * r, origin[1] + 0.5 * prob.shape[0] * r, 0.0)
            out.append(FrozenSubmap(centre, grid, pyramid(values, depth), (1 << (depth - 1)) - 1))
    return tuple(out)


def frozen_submaps(map_: object, size_m: float, depth: int) -> tuple[FrozenSubmap, ...]:
    """The map's frozen submaps (module notes), built once per map and parameters."""
    return cached(map_, ("cartographer-frozen", round(size_m, 9), int(depth)),
                  lambda: _build(map_, size_m, depth))


def search(sub: FrozenSubmap, points: np.ndarray, initial: Pose, linear_window: float,
           angular_window: float, min_score: float) -> tuple[Pose, float] | None:
    """Branch and bound of robot-frame ``points`` ``(N ≥ 1, 2)`` about ``initial`` (global frame)
    in ``sub``: the best pose and its score, or ``None`` when no candidate exceeds ``min_score``."""
    g = sub.grid
    r = g.resolution
    step = angular_step(float(np.max(np.hypot(points[:, 0], points[:, 1]))), r)
    na = int(math.ceil(angular_window / step))
    thetas = initial.theta + step * np.arange(-na, na + 1)
    c, s = np.cos(thetas)[:, None], np.sin(thetas)[:, None]
    wx = initial.x + c * points[None, :, 0] - s * points[None, :, 1]
    wy = initial.y + s * points[None, :, 0] + c * points[None, :, 1]
    offsets = np.ascontiguousarray(np.stack((np.floor((wx - g.origin[0]) / r), np.floor((wy - g.origin[1]) / r)),
                                            axis=-1).astype(np.int32))
    nl = int(math.ceil(linear_window / r))
    min_sum = (min_score - MIN_PROBABILITY) * _SCALE * len(points)
    hk, hx, hy, hs, count, _ = branch_and_bound(sub.grids, sub.pad, offsets, -nl, nl, -nl, nl, float(min_sum),
                                                1, 0.0, 0)
    if count == 0:
        return None
    pose = Pose(initial.x + hx[0] * r, initial.y + hy[0] * r, float(wrap_angle(thetas[hk[0]])))
    return pose, float(MIN_PROBABILITY + hs[0] / (_SCALE * len(points)))


def search_full(sub: FrozenSubmap, points: np.ndarray, min_score: float) -> tuple[Pose, float] | None:
    """``MatchFullSubmap``: every heading, shifts covering the whole tile (module notes)."""
    reach = float(np.max(np.hypot(points[:, 0], points[:, 1])))
    half = 0.5 * max(sub.grid.prob.shape) * sub.grid.resolution
    return search(sub, points, sub.pose, half + reach, math.pi, min_score)
