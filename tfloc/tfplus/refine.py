"""Point-to-line refinement of poses against their virtual scans (``tf-plus``'s last stage).

Each iteration simulates the virtual scan at every candidate pose (one batched
:meth:`Map.raycast`, so it works for any map), associates each real point with the nearest
virtual point within a few beams of the same bearing, takes the virtual scan's local line
direction there (from its neighbouring points), and makes Gauss–Newton steps on SE(2) that
minimise the point-to-line distances of the associated pairs. Pairs farther apart than a gate
that shrinks from ``gate_start`` to ``gate_end`` are ignored, so walls the map lacks (or the
map has and the scan misses) do not pull. All candidates are refined together, vectorised.

The pose update is in the frame of the current virtual scan: with ``δ = (tx, ty, φ)`` mapping
real points ``p`` (sensor frame) to ``R(φ) p + t`` in the virtual pose's frame, the new pose is
``pose ⊕ δ``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.pose import wrap_angle

from .kernels import pairs_kernel


@dataclass(frozen=True)
class RefineConfig:
    """Parameters of the point-to-line refinement.

    Attributes:
        iterations: virtual scans simulated per candidate (outer iterations).
        inner: Gauss–Newton steps per virtual scan, re-associating each time.
        window: beams either side of the bearing searched for the nearest virtual point.
        gate_start: pair distance gate of the first iteration (metres).
        gate_end: pair distance gate of the last iteration (metres).
        inlier_distance: truncation of the residual used to rank candidates (metres).
        damping: Levenberg–Marquardt damping added to the normal equations.
        prune_after: after this many iterations only the ``keep`` candidates with the lowest
            truncated residual go on, duplicates (within 5 cm of a better one) dropped
            (0: never prune).
        keep: see ``prune_after``.
    """

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("gate_start", "gate_end", "inlier_distance"),
        ">= 0": ("window", "damping", "prune_after"),
        ">= 1": ("iterations", "inner", "keep")}

    iterations: int = 6
    inner: int = 2
    window: int = 6
    gate_start: float = 0.5
    gate_end: float = 0.05
    inlier_distance: float = 0.05
    damping: float = 1e-6
    prune_after: int = 3
    keep: int = 2


def _virtual_geometry(ranges: np.ndarray, laser: LaserSpec) -> tuple[np.ndarray, np.ndarray]:
    """Virtual points ``(K, n, 2)`` (NaN for no return) and unit line normals ``(K, n, 2)``."""
    ok = laser.valid(ranges)
    r = np.where(ok, ranges, np.nan)
    q = np.stack((np.cos(laser.angles) * r, np.sin(laser.angles) * r), axis=-1)
    fwd = np.full_like(q, np.nan)
    fwd[:, :-1] = q[:, 1:] - q[:, :-1]
    bwd = np.full_like(q, np.nan)
    bwd[:, 1:] = q[:, 1:] - q[:, :-1]
    lf, lb = np.hypot(fwd[..., 0], fwd[..., 1]), np.hypot(bwd[..., 0], bwd[..., 1])
    lf, lb = np.where(np.isnan(lf), np.inf, lf), np.where(np.isnan(lb), np.inf, lb)
    # central difference on smooth stretches, the shorter side across a jump or a corner
    central = (lf < 3 * lb) & (lb < 3 * lf)
    tangent = np.where(central[..., None], fwd + bwd, np.where((lf <= lb)[..., None], fwd, bwd))
    norm = np.hypot(tangent[..., 0], tangent[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        normal = np.stack((-tangent[..., 1], tangent[..., 0]), axis=-1) / norm[..., None]
    return q, normal


def _compose(poses: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """``pose ⊕ δ`` row-wise for ``(K, 3)`` arrays."""
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    return np.column_stack((poses[:, 0] + c * delta[:, 0] - s * delta[:, 1],
                            poses[:, 1] + s * delta[:, 0] + c * delta[:, 1],
                            wrap_angle(poses[:, 2] + delta[:, 2])))


def residuals_to(virtual: np.ndarray, laser: LaserSpec, points: np.ndarray, window: int = 6,
                 gate: float = 1.0) -> np.ndarray:
    """Point-to-line distances ``(K, M)`` (metres) of the real ``points`` ``(M, 2)`` against given
    virtual scans ``(K, n_beams)`` (ranges, metres, seen from the pose each real point is placed
    at); NaN where a point has no virtual neighbour within ``gate``."""
    q, normal = _virtual_geometry(virtual, laser)
    _, _, r = pairs_kernel(np.ascontiguousarray(points, dtype=float), np.zeros((len(virtual), 3)),
                           q, normal, laser.angle_min, laser.resolution, window, gate)
    return np.abs(r)


def truncated_cost(residuals: np.ndarray, inlier_distance: float) -> np.ndarray:
    """Mean squared residual truncated at ``inlier_distance`` (metres²), per row; NaN counts as far."""
    r = np.where(np.isnan(residuals), inlier_distance, np.minimum(residuals, inlier_distance))
    return np.mean(r * r, axis=-1)


def refine(map_: Map, laser: LaserSpec, points: np.ndarray, poses: np.ndarray,
           config: RefineConfig = RefineConfig()) -> np.ndarray:
    """Refine ``(K, 3)`` poses so the real ``points`` ``(M, 2)`` (sensor frame) lie on the map.

    Returns the refined poses: all ``K``, or the ``keep`` best if pruning is on (see
    :class:`RefineConfig`)."""
    poses = np.array(poses, dtype=float).reshape(-1, 3)
    points = np.ascontiguousarray(points, dtype=float)
    cfg = config
    gates = np.geomspace(cfg.gate_start, cfg.gate_end, max(cfg.iterations, 1))
    for it in range(cfg.iterations):
        q, normal = _virtual_geometry(map_.raycast(poses, laser), laser)
        delta = np.zeros_like(poses)
        for _ in range(cfg.inner):
            h, g, r = pairs_kernel(points, delta, q, normal, laser.angle_min, laser.resolution,
                                   cfg.window, gates[it])
            enough = (~np.isnan(r)).sum(axis=1) >= 3
            if enough.any():
                h = h[enough] + cfg.damping * np.eye(3)
                delta[enough] -= np.linalg.solve(h, g[enough][..., None])[..., 0]
        poses = _compose(poses, delta)
        if it + 1 == cfg.prune_after and len(poses) > cfg.keep:
            poses = _prune(poses, truncated_cost(np.abs(r), cfg.inlier_distance), cfg.keep)
    return poses


def _prune(poses: np.ndarray, cost: np.ndarray, keep: int, same: float = 0.05) -> np.ndarray:
    """The ``keep`` lowest-cost poses, counting poses within ``same`` metres of a better one
    (converged to the same place) once."""
    kept: list[int] = []
    for i in np.argsort(cost, kind="stable"):
        if all(np.hypot(*(poses[i, :2] - poses[j, :2])) >= same for j in kept):
            kept.append(int(i))
            if len(kept) == keep:
                break
    return poses[np.sort(kept)]
