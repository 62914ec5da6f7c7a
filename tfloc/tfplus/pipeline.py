"""``tf-plus``'s default configuration in one compiled call per scan, on vector and grid maps.

The staged path (:meth:`~tfloc.tfplus.matcher.TurningFunctionPlusMatcher.localize`) runs a dozen
compiled kernels glued by Python (map-view look-ups, argument conversions, small arrays), and that
glue costs a good part of a call once other matchers have run in between and the interpreter's
own objects are cold (measured: ``docs/tf-plus.md``, "The one-call pipeline"). Here the same
kernels run in one compiled call, fed by a :class:`Plan` of everything that depends on the map,
the laser and the configuration alone (built once per map): per scan, one dispatch from Python.

Same arithmetic, same order, same kernels: the poses and costs are those of the staged path bit
for bit (``tests/tfplus/test_pipeline.py`` runs both). The plan covers the default stage
switches (the heading sweep with or without turning-function seeds, the coarse grid, the
refinement, ``select="residual"``; on a vector map against virtual scans or the map itself, on a grid map
against the map itself); every other configuration, another kind of map, or a vector map whose
free-space tests are not built, goes the staged way (:func:`plan_for` returns ``None``), and so
does a scan whose lattice the compiled free-space test cannot decide (status
:data:`UNDECIDED`).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from tfloc.core.laser import LaserSpec, _returns_to_points
from tfloc.maps._gridcast import raycast_grid
from tfloc.maps._raycast import raycast_segments
from tfloc.maps.cache import cached
from tfloc.maps.grid import GridMap
from tfloc.maps.inside import SURE
from tfloc.maps.vector import VectorMap

from . import refine as refine_module
from . import unmapped as unmapped_module
from .coarse import _offsets
from .coarse_kernel import coarse_kernel, grid_lattice_kernel, lattice_kernel
from .config import TfPlusConfig, coarse_search, field_view, heading_offsets, sweep
from .cost_kernel import (
    beam_flags_kernel,
    grid_cost_kernel,
    object_groups_kernel,
    unmapped_kernel,
    vector_cost_kernel,
    vector_short_mask,
)
from .field_kernel import refine_to_field_kernel
from .headings import _pair_kernel, _scan_rotations
from .unmapped import refine_each_kernel
from .virtual_kernel import prune_index_kernel, refine_vector_kernel

if TYPE_CHECKING:
    from tfloc.core.problem import Problem

OK, TOO_FEW, UNDECIDED = 0, 1, 2  #: statuses of the pipeline kernels

_BINS = 720                       # the heading histograms' bins and smoothing (radians), as
_SMOOTHING = float(np.radians(1.0))  # :func:`tfloc.tfplus.headings.scan_rotations` defaults them


@dataclass(frozen=True, eq=False)
class Plan:
    """What :func:`run` passes to its kernel besides the scan: ``kind`` ``"vector"`` (refined
    against virtual scans), ``"vector-field"`` (a vector map, refined against the map itself) or
    ``"grid"``, and the kernel's static arguments (arrays and numbers of the map's views, the
    laser and the configuration; metres, radians)."""

    kind: str
    args: tuple


_last: tuple | None = None  # (map, laser, configuration, plan) of the last plan_for, weakly


def plan_for(problem: Problem, cfg: TfPlusConfig) -> Plan | None:
    """The plan of ``problem``'s map and laser under ``cfg`` (built once per map, laser and
    configuration), or ``None`` where the staged path must serve (see the module docstring)."""
    global _last
    last = _last
    if (last is not None and last[1] is problem.laser and last[2] is cfg
            and last[0]() is problem.map):
        plan = last[3]()
        if plan is not None:
            return plan
    plan = _plan_of(problem.map, problem.laser, cfg)
    if plan is not None:
        try:
            _last = (weakref.ref(problem.map), problem.laser, cfg, weakref.ref(plan))
        except TypeError:                      # a map that cannot be weakly referenced
            _last = None
    return plan


def _plan_of(map_: object, laser: LaserSpec, cfg: TfPlusConfig) -> Plan | None:
    """:func:`plan_for` without its memo of the last call."""
    if not (cfg.heading_sweep and cfg.grid and cfg.refine and cfg.select == "residual"):
        return None
    if isinstance(map_, VectorMap):
        if map_.area_rings() is None or map_.free_rings() is None:
            return None                      # not built (a map used once): the staged path
        kind = "vector-field" if cfg.refine_to == "field" else "vector"
    elif isinstance(map_, GridMap):
        if cfg.refine_to not in ("auto", "field"):
            return None
        kind = "grid"
    else:
        return None
    return cached(map_, ("tf-plus-plan", laser, cfg), lambda: _build(map_, laser, cfg, kind))


def _build(map_: VectorMap | GridMap, laser: LaserSpec, cfg: TfPlusConfig, kind: str) -> Plan:
    """The :class:`Plan`: the same values the staged path computes per call."""

    field = field_view(map_, cfg)
    cos_a, sin_a = refine_module._beam_trig(laser)
    max_range = float(laser.max_range)
    beams = (np.asarray(laser.angles, dtype=float), laser.directions, cos_a, sin_a,
             float(laser.angle_min), float(laser.resolution), max_range)
    shape = cfg.shape
    width = 2 * np.pi / _BINS
    rotation = (float(shape.spacing), int(shape.window), float(shape.straw_t),
                float(shape.line_threshold), bool(shape.close_through_origin),
                shape.resampling == "path", _BINS, True, _pair_kernel(_BINS, _SMOOTHING),
                int(np.floor(cfg.max_rotation / width)), int(cfg.rotation_seeds))
    headings = (sweep(cfg.heading_span, cfg.heading_step), heading_offsets(cfg.heading_offsets),
                bool(cfg.tf_seed))
    corner = field.origin
    lattice = (_offsets(float(cfg.search_radius), float(cfg.grid_step)), field.table,
               float(corner[0]), float(corner[1]), field.resolution,
               field.table.dtype.type(cfg.clearance))
    coarse = coarse_search(map_, cfg)
    r = cfg.refinement
    gates = refine_module._gates(r)
    view = (field.nearest, float(field.origin[0]), float(field.origin[1]), field.resolution,
            field.points, field.normals)
    select = (-1.0 if cfg.short_residual is None else float(cfg.short_residual),  # -1: off
              float(cfg.see_through_share), float(cfg.short_margin),
              -1.0 if cfg.object_extent is None else float(cfg.object_extent))      # -1: off
    gate = float(cfg.short_margin) if cfg.short_refine else -1.0                   # -1: off
    gate_parts = unmapped_module.split(refine_module.field_refinement(field, r), int(r.prune_after))
    common = (beams, rotation, headings, lattice, coarse, view, int(cfg.min_returns),
              int(r.iterations), float(r.inlier_distance), bool(cfg.beam_check), select, gate,
              gate_parts + (int(r.keep),))
    if kind != "grid":
        free = (map_.area_rings().kernel, map_.free_rings().kernel, SURE)
        vector = (free, map_.segments, map_.segment_index(max_range))
        if kind == "vector-field":
            return Plan(kind, common + (refine_module.field_refinement(field, r),) + vector)
        refine = (gates, int(r.inner), int(r.window), float(r.damping), int(r.prune_after),
                  int(r.keep))
        return Plan(kind, common + (refine,) + vector)
    refine = refine_module.field_refinement(field, r)
    grid = (map_.occupied, float(map_.origin[0]), float(map_.origin[1]), float(map_.resolution),
            map_.free, map_.distance)
    return Plan(kind, common + (refine, grid))


def run(plan: Plan, ranges: np.ndarray, x: float, y: float, theta: float) -> tuple:
    """The pipeline on one scan (``ranges``, metres) from the initial guess ``(x, y, theta)``:
    ``(status, returns, poses (K, 3), cost (K,), rotations, seeded, evaluations)`` — the refined
    candidates and their selection cost (metres²), the turning-function rotations (radians;
    ``seeded`` false: no turning function) and the evaluations counted as the staged path counts
    them. Status :data:`TOO_FEW`: fewer than ``min_returns`` returns; :data:`UNDECIDED`: the
    lattice needs the map's own free-space test (nothing else is computed then)."""
    return _KERNELS[plan.kind](ranges, x, y, theta, *plan.args)


@njit(cache=True, nogil=True)
def _headings(theta: float, sweep: np.ndarray, offsets: np.ndarray, rotations: np.ndarray,
              seeded: bool) -> np.ndarray:
    """:func:`tfloc.tfplus.matcher.heading_seeds`'s headings: ``θ + sweep``, then
    ``(θ − rotation) + offset`` for each rotation × offset (radians)."""
    n_s, n_o = sweep.shape[0], offsets.shape[0]
    n_r = rotations.shape[0] if seeded else 0
    out = np.empty(n_s + n_r * n_o)
    for i in range(n_s):
        out[i] = theta + sweep[i]
    k = n_s
    for r in range(n_r):
        base = theta - rotations[r]
        for o in range(n_o):
            out[k] = base + offsets[o]
            k += 1
    return out


@njit(cache=True, nogil=True)
def _seeded_headings(ranges: np.ndarray, virtual: np.ndarray, theta: float, beams: tuple,
                     rotation: tuple, headings: tuple) -> tuple[np.ndarray, np.ndarray, bool]:
    """The turning-function rotations of the real scan against the virtual one at the VP
    (:func:`tfloc.tfplus.headings._scan_rotations`) and the coarse search's headings; without
    seeds (``tf_seed`` off: ``headings[2]``) the sweep alone, ``virtual`` unread."""
    if not headings[2]:
        none = np.empty(0)
        return none, _headings(theta, headings[0], headings[1], none, False), False
    spacing, window, straw_t, line_threshold, close, along, bins, skip, g2, k_max, count = rotation
    rots, seeded = _scan_rotations(ranges, virtual, beams[1], beams[6], spacing, window, straw_t,
                                   line_threshold, close, along, bins, skip, g2, k_max, count)
    return rots, _headings(theta, headings[0], headings[1], rots, seeded), seeded


@njit(cache=True, nogil=True)
def _at(x: float, y: float, theta: float) -> np.ndarray:
    """The pose ``(x, y, theta)`` as a ``(1, 3)`` array, for a ray cast."""
    pose = np.empty((1, 3))
    pose[0, 0], pose[0, 1], pose[0, 2] = x, y, theta
    return pose


@njit(cache=True, nogil=True)
def _no_poses(status: int, returns: int, rotations: np.ndarray, seeded: bool) -> tuple:
    """:func:`run`'s answer with no candidates (status :data:`TOO_FEW` or :data:`UNDECIDED`)."""
    return status, returns, np.empty((0, 3)), np.empty(0), rotations, seeded, 0


@njit(cache=True, nogil=True)
def _vector_coarse(ranges: np.ndarray, x: float, y: float, theta: float, beams: tuple,
                   rotation: tuple, headings: tuple, lattice: tuple, coarse: tuple,
                   min_returns: int, free: tuple, segs: np.ndarray, index: tuple) -> tuple:
    """The pipeline on a vector map up to the coarse candidates: ``(status, points, rotations,
    seeded, candidates, evaluations)``."""
    angles, directions, cos_a, sin_a, angle_min, resolution, max_range = beams
    points = _returns_to_points(ranges, directions, max_range)
    if points.shape[0] < min_returns:
        return TOO_FEW, points, np.empty(0), False, np.empty((0, 3)), 0
    virtual = (raycast_segments(_at(x, y, theta), angles, segs, max_range, index)[0]
               if headings[2] else ranges)
    rots, heads, seeded = _seeded_headings(ranges, virtual, theta, beams, rotation, headings)
    offsets, table, corner_x, corner_y, res, clearance = lattice
    positions, decided = lattice_kernel(x, y, offsets, table, corner_x, corner_y, res, clearance,
                                        free[0], free[1], free[2])
    if not decided:
        return UNDECIDED, points, rots, seeded, np.empty((0, 3)), 0
    cands, evaluations = coarse_kernel(points, positions, x, y, heads, coarse)
    return OK, points, rots, seeded, cands, evaluations


@njit(cache=True, nogil=True)
def _groups(ranges: np.ndarray, beams: tuple, select: tuple) -> np.ndarray:
    """:func:`tfloc.tfplus.cost.object_groups` of the scan."""
    return object_groups_kernel(ranges, beams[1], beams[6], beams[5], select[3])


@njit(cache=True, nogil=True)
def _vector_cost(ranges: np.ndarray, cands: np.ndarray, beams: tuple, view: tuple, inlier: float,
                 beam_check: bool, select: tuple, groups: np.ndarray, vector: tuple) -> np.ndarray:
    """The selection cost of the candidates on a vector map (``vector``: its segments and their
    index)."""
    nearest, fx, fy, fres, map_points, map_normals = view
    return vector_cost_kernel(nearest, fx, fy, fres, map_points, map_normals, ranges, beams[1],
                              beams[0], beams[6], cands, vector[0], vector[1], inlier, beam_check,
                              select[0], select[1], select[2], groups)


@njit(cache=True, nogil=True)
def _grid_cost(ranges: np.ndarray, cands: np.ndarray, beams: tuple, view: tuple, inlier: float,
               beam_check: bool, select: tuple, groups: np.ndarray, grid: tuple) -> np.ndarray:
    """The selection cost of the candidates on a grid map (``grid``: the plan's grid tuple)."""
    nearest, fx, fy, fres, map_points, map_normals = view
    occupied, gx, gy, cell, free, _ = grid
    return grid_cost_kernel(nearest, fx, fy, fres, map_points, map_normals, ranges, beams[1],
                            beams[0], beams[6], cands, occupied, gx, gy, cell, inlier, beam_check,
                            free, select[0], select[1], select[2], groups)


@njit(cache=True, nogil=True)
def _vector_short(ranges: np.ndarray, cands: np.ndarray, beams: tuple, inlier: float,
                  gate: float, groups: np.ndarray, vector: tuple) -> np.ndarray:
    """The short returns ``(K, n)`` at the candidates on a vector map (its ray-cast ranges)."""
    virtual = raycast_segments(cands, beams[0], vector[0], beams[6], vector[1])
    return vector_short_mask(ranges, virtual, beams[6], gate)


@njit(cache=True, nogil=True)
def _grid_short(ranges: np.ndarray, cands: np.ndarray, beams: tuple, inlier: float, gate: float,
                groups: np.ndarray, grid: tuple) -> np.ndarray:
    """The short returns ``(K, n)`` at the candidates on a grid map (the grid walk's)."""
    occupied, gx, gy, cell, free, _ = grid
    return beam_flags_kernel(occupied, free, gx, gy, cell, cands, beams[0], ranges, beams[6],
                             inlier, gate, False, groups >= 0)[1]


def _refined_kernel(cost, short):
    """The refinement against the map itself for one kind of map, whose selection cost and short
    returns are ``cost`` and ``short`` (the ``_vector_*`` or ``_grid_*`` kernels above):
    :func:`refine_to_field_kernel`, or with a ``gate`` (``short_refine``) each candidate on its
    own returns (:mod:`tfloc.tfplus.unmapped`), pruned by the selection cost between the gate's
    two parts. numba resolves ``cost`` and ``short`` when it compiles a pipeline kernel, whose
    cache then holds them; called from Python the kernel made here would compile in every process
    (a closure's cache key pickles the jitted functions it holds, each with a per-process id)."""

    @njit(cache=True, nogil=True)
    def refined(ranges: np.ndarray, points: np.ndarray, cands: np.ndarray, beams: tuple,
                view: tuple, inlier: float, beam_check: bool, select: tuple, groups: np.ndarray,
                gate: float, gate_parts: tuple, refine: tuple, min_returns: int,
                where: tuple) -> np.ndarray:
        if gate < 0.0:
            return refine_to_field_kernel(view, points, cands, inlier, refine)
        first, second, more, keep = gate_parts
        for part in range(2 if more else 1):
            if part == 1 and cands.shape[0] > keep:
                costs = cost(ranges, cands, beams, view, inlier, beam_check, select, groups, where)
                cands = cands[prune_index_kernel(cands, costs, keep, 0.05)]
            unmapped = unmapped_kernel(short(ranges, cands, beams, inlier, gate, groups, where),
                                       groups)
            cands = refine_each_kernel(view, points, ranges, cands, inlier,
                                       first if part == 0 else second, unmapped, beams[6],
                                       min_returns, gate)
        return cands

    return refined


_vector_refined = _refined_kernel(_vector_cost, _vector_short)
_grid_refined = _refined_kernel(_grid_cost, _grid_short)


@njit(cache=True, nogil=True)
def vector_pipeline_kernel(ranges: np.ndarray, x: float, y: float, theta: float, beams: tuple,
                           rotation: tuple, headings: tuple, lattice: tuple, coarse: tuple,
                           view: tuple, min_returns: int, iterations: int, inlier: float,
                           beam_check: bool, select: tuple, gate: float, gate_parts: tuple,
                           refine: tuple, free: tuple, segs: np.ndarray, index: tuple) -> tuple:
    """:func:`run` on a vector map, refined against virtual scans (``Plan.args``; see
    :func:`_build`)."""
    status, points, rots, seeded, cands, evaluations = _vector_coarse(
        ranges, x, y, theta, beams, rotation, headings, lattice, coarse, min_returns, free, segs,
        index)
    if status != OK:
        return _no_poses(status, points.shape[0], rots, seeded)
    angles, directions, cos_a, sin_a, angle_min, resolution, max_range = beams
    gates, inner, window, damping, prune_after, keep = refine
    cands = refine_vector_kernel(cands, points, angles, cos_a, sin_a, angle_min, resolution,
                                 segs, index, max_range, gates, inner, window, damping,
                                 prune_after, keep, inlier)
    evaluations += cands.shape[0] * iterations
    cost = _vector_cost(ranges, cands, beams, view, inlier, beam_check, select,
                        _groups(ranges, beams, select), (segs, index))
    return OK, points.shape[0], cands, cost, rots, seeded, evaluations


@njit(cache=True, nogil=True)
def vector_field_pipeline_kernel(ranges: np.ndarray, x: float, y: float, theta: float,
                                 beams: tuple, rotation: tuple, headings: tuple, lattice: tuple,
                                 coarse: tuple, view: tuple, min_returns: int, iterations: int,
                                 inlier: float, beam_check: bool, select: tuple, gate: float,
                                 gate_parts: tuple, refine: tuple, free: tuple, segs: np.ndarray,
                                 index: tuple) -> tuple:
    """:func:`run` on a vector map, refined against the map itself (``refine_to="field"``)."""
    status, points, rots, seeded, cands, evaluations = _vector_coarse(
        ranges, x, y, theta, beams, rotation, headings, lattice, coarse, min_returns, free, segs,
        index)
    if status != OK:
        return _no_poses(status, points.shape[0], rots, seeded)
    groups = _groups(ranges, beams, select)
    cands = _vector_refined(ranges, points, cands, beams, view, inlier, beam_check, select, groups,
                            gate, gate_parts, refine, min_returns, (segs, index))
    evaluations += cands.shape[0] * iterations
    cost = _vector_cost(ranges, cands, beams, view, inlier, beam_check, select, groups,
                        (segs, index))
    return OK, points.shape[0], cands, cost, rots, seeded, evaluations


@njit(cache=True, nogil=True)
def grid_pipeline_kernel(ranges: np.ndarray, x: float, y: float, theta: float, beams: tuple,
                         rotation: tuple, headings: tuple, lattice: tuple, coarse: tuple,
                         view: tuple, min_returns: int, iterations: int, inlier: float,
                         beam_check: bool, select: tuple, gate: float, gate_parts: tuple,
                         refine: tuple, grid: tuple) -> tuple:
    """:func:`run` on a grid map (``Plan.args``; see :func:`_build`)."""
    angles, directions, max_range = beams[0], beams[1], beams[6]
    occupied, gx, gy, cell, free, distance = grid
    points = _returns_to_points(ranges, directions, max_range)
    if points.shape[0] < min_returns:
        return _no_poses(TOO_FEW, points.shape[0], np.empty(0), False)
    virtual = (raycast_grid(_at(x, y, theta), angles, occupied, gx, gy, cell, max_range)[0]
               if headings[2] else ranges)
    rots, heads, seeded = _seeded_headings(ranges, virtual, theta, beams, rotation, headings)
    offsets, table, corner_x, corner_y, res, clearance = lattice
    positions = grid_lattice_kernel(x, y, offsets, table, corner_x, corner_y, res, clearance,
                                    gx, gy, cell, free, distance, 0.5 * cell)
    cands, evaluations = coarse_kernel(points, positions, x, y, heads, coarse)
    groups = _groups(ranges, beams, select)
    cands = _grid_refined(ranges, points, cands, beams, view, inlier, beam_check, select, groups,
                          gate, gate_parts, refine, min_returns, grid)
    evaluations += cands.shape[0] * iterations
    cost = _grid_cost(ranges, cands, beams, view, inlier, beam_check, select, groups, grid)
    return OK, points.shape[0], cands, cost, rots, seeded, evaluations


_KERNELS = {"vector": vector_pipeline_kernel, "vector-field": vector_field_pipeline_kernel,
            "grid": grid_pipeline_kernel}
