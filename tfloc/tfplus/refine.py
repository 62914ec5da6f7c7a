"""Point-to-line refinement of poses (``tf-plus``'s last stage): against the map itself
(:func:`refine_to_field`, used on grid maps) or against ray-cast virtual scans (:func:`refine`,
used on vector maps). Both make Gauss–Newton steps on the point-to-line distances (metres) of
the pairs closer than a gate that shrinks from ``gate_start`` to ``gate_end``.

**Against the map** (:func:`refine_to_field`). Each scan point, placed at the candidate pose,
takes the nearest map point of its cell and that point's normal
(:class:`~tfloc.tfplus.view.MapView`, built once per map): no scan is simulated and there is no
beam window, so nothing depends on the scanner's beam count or spacing. On a grid map two phases:

1. while the gate is wider than ``offset_gate``, the pose alone against the occupied cells'
   centres: robust, but free to slide across a wall drawn several cells thick;
2. then the pose and a fourth unknown, the **depth** (metres) of the scan's returns behind the
   walls' surfaces (:mod:`tfloc.maps.walls`): each point is also measured from its wall's
   surface on the sensor's side, weighted ``face_weight`` against ``cell_weight``. The depth
   starts at the median over the points, with a weak prior (``offset_prior``,
   ``offset_weight``, in units of one point) for a scan that sees walls from one side only.

Why: where in a thick wall the returns lie is a property of how the map was built (a few cm,
nearly the same for every scan of a map); fitted as an unknown, it keeps the answer within about
2 cm of the truth where the cells alone, or virtual scans that stop at a wall's first cell, drift
by the walls' thickness (measured: ``docs/tf-plus.md``, "Real logs").

**Against virtual scans** (:func:`refine`, ``refine_to="virtual"``). Each iteration ray-casts the
candidates' virtual scans (:meth:`Map.raycast`, any map) and pairs each real point with the
nearest virtual point within ``window`` beams of its bearing, along the virtual scan's local line
there. On a vector map the virtual scan is exact and pairs only with surfaces the sensor sees.
With ``δ = (tx, ty, φ)`` mapping real points ``p`` (sensor frame) to ``R(φ) p + t`` in the
virtual pose's frame, the new pose is ``pose ⊕ δ``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.pose import wrap_angle
from tfloc.maps.vector import VectorMap

from .field_kernel import field_pairs_kernel, refine_to_field_kernel
from .view import MapView
from .virtual_kernel import pairs_kernel, refine_vector_kernel


@dataclass(frozen=True)
class RefineConfig:
    """Parameters of the point-to-line refinement.

    Attributes:
        iterations: outer iterations (each with its gate; against virtual scans, one simulated
            scan per candidate).
        window: beams either side of the bearing searched for the nearest virtual point (only
            against virtual scans).
        inlier_distance: truncation of the residual used to rank candidates (metres). 10 cm:
            on real grid maps the residuals at the true pose spread over a few cm (the map's own
            registration error), which 5 cm (chosen on simulated scans) cut into.
        prune_after: after this many iterations only the ``keep`` candidates with the lowest
            truncated residual go on, duplicates (within 5 cm of a better one) dropped
            (0: never prune).
    """

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("gate_start", "gate_end", "inlier_distance"),
        ">= 0": ("window", "damping", "prune_after"),
        ">= 1": ("iterations", "inner", "keep")}

    iterations: int = 6
    inner: int = 2  #: Gauss–Newton steps per outer iteration, re-associating each time
    window: int = 6
    gate_start: float = 0.5  #: pair distance gate of the first iteration (metres)
    gate_end: float = 0.05  #: pair distance gate of the last iteration (metres)
    inlier_distance: float = 0.1
    damping: float = 1e-6  #: Levenberg–Marquardt damping added to the normal equations
    prune_after: int = 3
    keep: int = 2  #: candidates kept at ``prune_after``
    faces: bool = True  #: grid maps: points from the walls' surfaces too (phase 2)
    offset_prior: float = 0.025  #: prior depth of returns behind a surface (m; half a cell)
    offset_weight: float = 1.0  #: weight of that prior, in units of one point
    offset_gate: float = 0.1  #: phase 2 starts once the gate is at most this (metres)
    max_depth: float = 0.3  #: the depth starts within [0, max_depth] (metres)
    face_weight: float = 1.0  #: weight of the surface residuals in phase 2 ...
    cell_weight: float = 1.0  #: ... and of the cell residuals


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
    """Point-to-line distances ``(K, M)`` (metres) of the real ``points`` ``(M, 2)`` (sensor frame)
    against virtual scans ``(K, n_beams)`` (ranges, metres); NaN where a point has no virtual
    neighbour within ``gate``."""
    q, normal = _virtual_geometry(virtual, laser)
    _, _, r = pairs_kernel(np.ascontiguousarray(points, dtype=float), np.zeros((len(virtual), 3)),
                           q, normal, laser.angle_min, laser.resolution, window, gate,
                           *_beam_trig(laser))
    return np.abs(r)


@lru_cache(maxsize=32)
def _gates_of(start: float, end: float, iterations: int) -> np.ndarray:
    gates = np.geomspace(start, end, max(iterations, 1))[:iterations]
    gates.setflags(write=False)
    return gates


def _gates(cfg: RefineConfig) -> np.ndarray:
    """The pair gates (metres) of the iterations, shrinking geometrically from ``gate_start`` to
    ``gate_end`` (read-only; made once per configuration)."""
    return _gates_of(float(cfg.gate_start), float(cfg.gate_end), int(cfg.iterations))


def truncated_cost(residuals: np.ndarray, inlier_distance: float) -> np.ndarray:
    """Mean squared residual truncated at ``inlier_distance`` (metres²), per row; NaN counts as far."""
    r = np.where(np.isnan(residuals), inlier_distance, np.minimum(residuals, inlier_distance))
    return np.mean(r * r, axis=-1)


def refine(map_: Map, laser: LaserSpec, points: np.ndarray, poses: np.ndarray,
           config: RefineConfig = RefineConfig()) -> np.ndarray:
    """Refine ``(K, 3)`` poses so the real ``points`` ``(M, 2)`` (sensor frame) lie on the map.

    Returns the refined poses: all ``K``, or the ``keep`` best if pruning is on (see
    :class:`RefineConfig`). On a vector map one compiled call (:func:`_refine_vector`), on
    any other map :func:`_refine_steps`: the same poses."""
    poses = np.array(poses, dtype=float).reshape(-1, 3)
    points = np.ascontiguousarray(points, dtype=float)
    refine_with = _refine_vector if isinstance(map_, VectorMap) else _refine_steps
    return refine_with(map_, laser, points, poses, config, _gates(config))


def _refine_steps(map_: Map, laser: LaserSpec, points: np.ndarray, poses: np.ndarray,
                  cfg: RefineConfig, gates: np.ndarray) -> np.ndarray:
    """:func:`refine` on any map, step by step: per iteration one batched ray cast, the virtual
    scans' geometry, ``inner`` pairings and Gauss–Newton steps, and the pruning after
    ``prune_after`` iterations."""
    for it in range(cfg.iterations):
        q, normal = _virtual_geometry(map_.raycast(poses, laser), laser)
        delta = np.zeros_like(poses)
        for _ in range(cfg.inner):
            h, g, r = pairs_kernel(points, delta, q, normal, laser.angle_min, laser.resolution,
                                   cfg.window, gates[it], *_beam_trig(laser))
            enough = (~np.isnan(r)).sum(axis=1) >= 3
            if enough.any():
                h = h[enough] + cfg.damping * np.eye(3)
                delta[enough] -= np.linalg.solve(h, g[enough][..., None])[..., 0]
        poses = _compose(poses, delta)
        if it + 1 == cfg.prune_after and len(poses) > cfg.keep:
            poses = _prune(poses, truncated_cost(np.abs(r), cfg.inlier_distance), cfg.keep)
    return poses


def _refine_vector(map_: VectorMap, laser: LaserSpec, points: np.ndarray, poses: np.ndarray,
                   cfg: RefineConfig, gates: np.ndarray) -> np.ndarray:
    """:func:`refine` on a vector map in one compiled call
    (:func:`~tfloc.tfplus.virtual_kernel.refine_vector_kernel`: the iterations, the pruning
    between them): the same poses as the step-by-step loop, without its per-iteration Python and
    numpy overhead."""
    cos_a, sin_a = _beam_trig(laser)
    return refine_vector_kernel(poses, points, laser.angles, cos_a, sin_a,
                                float(laser.angle_min), float(laser.resolution), map_.segments,
                                map_.segment_index(float(laser.max_range)), float(laser.max_range),
                                gates, cfg.inner, cfg.window,
                                cfg.damping, cfg.prune_after, cfg.keep, cfg.inlier_distance)


_TRIG: dict = {}


def _beam_trig(laser: LaserSpec) -> tuple[np.ndarray, np.ndarray]:
    """``(cos, sin)`` of the beam angles, as numpy computes them (cached per laser)."""
    key = (laser.angle_min, laser.resolution, laser.n_beams)
    hit = _TRIG.get(key)
    if hit is None:
        hit = _TRIG[key] = (np.cos(laser.angles), np.sin(laser.angles))
    return hit


def _prune(poses: np.ndarray, cost: np.ndarray, keep: int, same: float = 0.05) -> np.ndarray:
    """The ``keep`` lowest-cost poses, counting poses within ``same`` metres of a better one
    (converged to the same place) once."""
    return poses[_prune_index(poses, cost, keep, same)]


def _prune_index(poses: np.ndarray, cost: np.ndarray, keep: int, same: float = 0.05) -> np.ndarray:
    """Indices (ascending) of the poses :func:`_prune` keeps."""
    kept: list[int] = []
    for i in np.argsort(cost, kind="stable"):
        if all(np.hypot(*(poses[i, :2] - poses[j, :2])) >= same for j in kept):
            kept.append(int(i))
            if len(kept) == keep:
                break
    return np.sort(np.array(kept, dtype=np.int64))


def field_pairs(field: MapView, points: np.ndarray, poses: np.ndarray, gate: float,
                offsets: np.ndarray | None = None, face_weight: float = 0.0,
                cell_weight: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`~tfloc.tfplus.field_kernel.field_pairs_kernel` on a field: ``H`` ``(K, 4, 4)``, ``g``
    ``(K, 4)``, residuals ``(K, M)`` to the nearest map points (NaN: farther than ``gate``) and
    ranking residuals ``(K, M)`` (metres) of scan ``points`` ``(M, 2)`` at world ``poses``
    ``(K, 3)``. On a grid map the system weighs the residuals to the walls' surfaces by
    ``face_weight`` (the returns lying ``offsets`` ``(K,)`` metres behind them) and those to the
    occupied cells' centres by ``cell_weight``; otherwise it holds the latter alone."""
    poses = np.ascontiguousarray(np.reshape(poses, (-1, 3)), dtype=float)
    offsets = np.zeros(len(poses)) if offsets is None else np.ascontiguousarray(offsets, dtype=float)
    faces = field.faces and face_weight > 0
    return field_pairs_kernel(field.nearest, float(field.origin[0]), float(field.origin[1]),
                              field.resolution, field.points, field.normals, field.face_plus,
                              field.face_minus, np.ascontiguousarray(points, dtype=float), poses,
                              offsets, gate, field.resolution, cell_weight if faces else 1.0,
                              face_weight if faces else 0.0)


def field_refinement(field: MapView, cfg: RefineConfig) -> tuple:
    """What :func:`~tfloc.tfplus.field_kernel.refine_to_field_kernel` takes of ``cfg`` and of the
    map's view besides the view's look-up arrays: the gates, the Gauss–Newton and pruning
    parameters, whether the walls' surfaces are used, the surfaces' distances and the depth's
    weights and bounds."""
    return (_gates(cfg), int(cfg.inner), float(cfg.damping), int(cfg.prune_after), int(cfg.keep),
            bool(cfg.faces and field.faces), bool(field.faces), field.face_plus, field.face_minus,
            float(cfg.offset_gate), float(cfg.face_weight), float(cfg.cell_weight),
            float(cfg.offset_weight), float(cfg.offset_prior), float(cfg.max_depth))


def refine_to_field(field: MapView, points: np.ndarray, poses: np.ndarray,
                    config: RefineConfig = RefineConfig()) -> np.ndarray:
    """Refine ``(K, 3)`` world poses so the scan ``points`` ``(M, 2)`` (sensor frame) lie on the
    map (see the module docstring). Returns all ``K`` refined poses, or the ``keep`` best if
    pruning is on (see :class:`RefineConfig`). One compiled call
    (:func:`~tfloc.tfplus.field_kernel.refine_to_field_kernel`)."""
    view = (field.nearest, float(field.origin[0]), float(field.origin[1]), field.resolution,
            field.points, field.normals)
    return refine_to_field_kernel(view, np.ascontiguousarray(points, dtype=float),
                                  np.array(poses, dtype=float).reshape(-1, 3),
                                  float(config.inlier_distance), field_refinement(field, config))
