"""``tf-plus``: the project's own turning-function localizer, built to win the convergence basin.

It keeps what the paper's turning function is good at and replaces what holds the faithful ``tf``
back: Eq. 13's cost is rugged at the centimetre scale (ShortStraw's corner set changes discretely
as the virtual pose moves), so ``tf``'s simplex stalls in local optima. Stages:

1. **Headings** (:func:`heading_seeds`): a sweep θ_VP ± ``heading_span`` (``heading_sweep``)
   plus turning-function seeds (``tf_seed``, :mod:`tfloc.tfplus.headings`): rotation offsets
   between the real and the virtual scan at the VP that need no position and no common
   starting vertex, ``θ = θ_VP − rotation``.
2. **Coarse grid** (:mod:`tfloc.tfplus.coarse`): every free lattice position within
   ``search_radius`` of the VP × those headings, scored on a truncated distance field of the
   map, smooth and free of the corner set's discreteness; pooled over ± half a lattice step
   (``coarse_bound``, Olson's bound) so that the lattice pose nearest the truth is not
   outscored for lying a few cm off a wall. The best ``candidates``, ``separation`` apart, go on.
3. **Point-to-line refinement** of every candidate (:mod:`tfloc.tfplus.refine`), with a
   shrinking outlier gate: on a grid map against the map itself (its walls are drawn several
   cells thick, and a virtual scan in it stops short), on a vector map against ray-cast
   virtual scans (``refine_to="auto"``).
4. **Selection** (:mod:`tfloc.tfplus.cost`): the lowest per-beam cost (``select="residual"``) or
   turning-function Err (``select="tf"``); candidates within ``tie_tolerance`` of the best (the
   scan sees the same geometry from both places) are a tie, won by the one nearest the VP.

In the default configuration on vector and grid maps the stages run in one compiled call per
scan (:mod:`tfloc.tfplus.pipeline`, the same answers). Each stage can be switched off or put back
as it was before the real logs, for the ablations; the measurements are in ``docs/tf-plus.md``.
It uses the :class:`~tfloc.core.map.Map` protocol, on a :class:`~tfloc.maps.grid.GridMap` also
its occupied cells, and never the true pose.
"""

from __future__ import annotations

import math

import numpy as np

from tfloc.core.params import Configured
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap
from tfloc.paper.shape import scan_turning_function
from tfloc.paper.turning import match

from . import pipeline
from .coarse import lattice, pose_scores
from .coarse_kernel import coarse_kernel
from .config import TfPlusConfig, coarse_search
from .config import coarse_view as _coarse_field
from .config import field_view as _field
from .config import heading_offsets as _heading_offsets
from .config import sweep as _sweep
from .cost import object_groups, scan_cost
from .headings import scan_rotations
from .refine import refine, refine_to_field
from .unmapped import refine_each_to_field


def heading_seeds(problem: Problem, cfg: TfPlusConfig) -> tuple[np.ndarray, dict]:
    """Headings (radians) for the coarse search, and what the turning function said.

    The sweep θ_VP ± ``heading_span`` (``heading_sweep``) and/or the turning-function seeds with
    ``heading_offsets`` around each (``tf_seed``); θ_VP with its offsets if neither is on."""
    th0 = problem.initial.theta
    info: dict = {}
    offsets = _heading_offsets(cfg.heading_offsets)
    heads = [th0 + (_sweep(cfg.heading_span, cfg.heading_step) if cfg.heading_sweep else offsets)]
    if cfg.tf_seed:
        rots = scan_rotations(problem.ranges, problem.map.raycast(problem.initial, problem.laser),
                              problem.laser, cfg.shape, cfg.max_rotation, cfg.rotation_seeds)
        if rots is not None:
            heads.append(((th0 - rots)[:, None] + offsets[None, :]).ravel())
            info = {"tf_rotations": rots.tolist()}
    return np.concatenate(heads), info


def tf_errs(problem: Problem, poses: np.ndarray, cfg: TfPlusConfig) -> np.ndarray:
    """Turning-function Err (Eq. 13, radians) at each of ``(K, 3)`` poses; inf if degenerate."""
    real = scan_turning_function(problem.ranges, problem.laser, cfg.shape)
    out = np.full(len(poses), np.inf)
    if real is None:
        return out
    for i, ranges in enumerate(problem.map.raycast(poses, problem.laser)):
        v = scan_turning_function(ranges, problem.laser, cfg.shape)
        if v is not None:
            out[i] = match(real, v).distance
    return out


def pick(cost: np.ndarray, poses: np.ndarray, vp: Pose, tie_tolerance: float) -> int:
    """Index of the answer: the lowest ``cost``, or, among the candidates within a factor
    ``1 + tie_tolerance`` of it (the scan cannot tell them apart), the one nearest the VP."""
    if len(cost) == 1:
        return 0
    costs = [float(c) for c in cost]        # a handful of candidates: plain floats
    best = min(costs)
    tied = [i for i, c in enumerate(costs) if c <= best * (1.0 + tie_tolerance)]
    if len(tied) == 1:
        return tied[0]
    near = [math.hypot(poses[i, 0] - vp.x, poses[i, 1] - vp.y) for i in tied]
    return tied[near.index(min(near))]


class TurningFunctionPlusMatcher(Configured):
    """``tf-plus``: turning-function heading seed, coarse grid, point-to-line refinement."""

    name = "tf-plus"
    CONFIG = TfPlusConfig

    def prepare(self, problem: Problem) -> None:
        """Build the map's view, its pooled copy and the free-space tests (once per map; untimed
        by the harness, once per dataset: a scan-to-scan dataset's per-scan maps never build
        the free-space tests, which pay only on a map queried many times)."""
        _field(problem.map, self.config)
        _coarse_field(problem.map, self.config)
        if isinstance(problem.map, VectorMap):   # the lattice's compiled free tests
            problem.map.area_rings(build=True)
            problem.map.free_rings(build=True)
        xy = problem.initial.xy[None, :]
        problem.map.in_bounds(xy)
        problem.map.is_free(xy)
        pipeline.plan_for(problem, self.config)  # the one-call pipeline's plan, if it applies

    def localize(self, problem: Problem) -> Estimate:
        """The stages of the module docstring: in one compiled call where the configuration and
        the map allow (:mod:`tfloc.tfplus.pipeline`, the same answers), else stage by stage."""
        cfg = self.config
        vp = problem.initial
        plan = pipeline.plan_for(problem, cfg)
        found = None
        if plan is not None:
            status, returns, cands, cost, rots, seeded, evaluations = pipeline.run(
                plan, problem.ranges, vp.x, vp.y, vp.theta)
            if status == pipeline.TOO_FEW:
                return self._no_answer(problem, returns)
            if status == pipeline.OK:
                info = {"tf_rotations": rots.tolist()} if seeded else {}
                found = cands, cost, info, evaluations
        if found is None:
            found = self._staged(problem)
            if found is None:
                return self._no_answer(problem, len(problem.points))
        cands, cost, info, evaluations = found
        b = pick(cost, cands, vp, cfg.tie_tolerance)
        pose = Pose.from_array(cands[b])
        info.update({"status": "ok", "candidates": len(cands), "cost": float(cost[b])})
        return Estimate(pose, True, 1, int(evaluations), info)

    def _no_answer(self, problem: Problem, returns: int) -> Estimate:
        """The answer to a scan with too few returns: the VP, not converged."""
        return Estimate(problem.initial, False, 0, 0, {
            "status": "no-answer", "reason": f"{returns} returns (< {self.config.min_returns})"})

    def _staged(self, problem: Problem) -> tuple[np.ndarray, np.ndarray, dict, int] | None:
        """The stages one call each: the refined candidates ``(K, 3)``, their selection cost
        ``(K,)``, what the turning function said and the evaluations; ``None`` with too few
        returns."""
        cfg = self.config
        points = problem.points
        if len(points) < cfg.min_returns:
            return None
        heads, info = heading_seeds(problem, cfg)
        vp = problem.initial
        if cfg.grid:
            field = _field(problem.map, cfg)
            positions = lattice(problem.map, field, vp.xy, cfg.search_radius, cfg.grid_step,
                                cfg.clearance)
            cands, evaluations = coarse_kernel(np.ascontiguousarray(points, dtype=float),
                                               np.ascontiguousarray(positions, dtype=float),
                                               vp.x, vp.y, np.ascontiguousarray(heads, dtype=float),
                                               coarse_search(problem.map, cfg))
        else:
            cands = np.column_stack((np.full(len(heads), vp.x), np.full(len(heads), vp.y), heads))
            if not cfg.refine:
                cands = cands[np.argsort(pose_scores(_field(problem.map, cfg), points, cands), kind="stable")[:1]]
            evaluations = len(heads)
        if cfg.refine:
            to = cfg.refine_to
            if to == "auto":
                to = "field" if isinstance(problem.map, GridMap) else "virtual"
            if to == "field" and cfg.short_refine:
                cands = refine_each_to_field(problem.map, problem.laser, problem.ranges,
                                             _field(problem.map, cfg), cands, cfg.refinement,
                                             cfg.short_margin, cfg.min_returns,
                                             object_groups(problem.laser, problem.ranges,
                                                           cfg.object_extent),
                                             lambda poses: self._cost(problem, poses))
            elif to == "field":
                cands = refine_to_field(_field(problem.map, cfg), points, cands, cfg.refinement)
            else:
                cands = refine(problem.map, problem.laser, points, cands, cfg.refinement)
            evaluations += len(cands) * cfg.refinement.iterations
        if cfg.select == "tf":
            cost = tf_errs(problem, cands, cfg)
        else:
            cost = self._cost(problem, cands)
        return cands, cost, info, evaluations

    def score(self, problem: Problem, pose: Pose) -> float:
        """The selection objective at ``pose`` (:func:`tfloc.tfplus.cost.scan_cost`), as its root
        (metres): the root mean square of the truncated per-beam residuals."""
        return float(np.sqrt(self._cost(problem, pose.as_array()[None, :])[0]))

    def _cost(self, problem: Problem, poses: np.ndarray) -> np.ndarray:
        """The selection cost (metres²) at ``(K, 3)`` poses (:func:`tfloc.tfplus.cost.scan_cost`)."""
        cfg = self.config
        field = _field(problem.map, cfg) if cfg.select != "virtual" else None
        return scan_cost(problem.map, problem.laser, problem.ranges, poses, cfg.refinement.window,
                         cfg.refinement.inlier_distance, cfg.beam_check, field,
                         cfg.short_residual,
                         cfg.see_through_share, cfg.short_margin, cfg.object_extent)


__all__ = ["TfPlusConfig", "TurningFunctionPlusMatcher", "heading_seeds", "pick", "tf_errs"]


REGISTRY = {"tf-plus": {"class": "TurningFunctionPlusMatcher", "docs": "tf-plus.md", "files": ["tfloc/tfplus/"], "summary": (
    "the project's own variant: turning-function heading seeds, a coarse grid on a distance "
    "field, batched point-to-line refinement, selection with a see-through check "
    "([docs/tf-plus.md](tf-plus.md), ablation: `benchmarks/tfplus-ablation.toml`). the preset"
    " `tf-plus-changed` is its **changed-world** configuration (`tfloc/presets.toml`: "
    "unmapped objects and missing furniture bounded in every stage; opt-in, "
    "[docs/robustness.md](robustness.md))")}}
