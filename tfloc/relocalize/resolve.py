"""Resolving many places at once with ``tf-plus``'s stages (an alternative to running its whole
``localize`` per place, ``resolve="batched"`` in ``tf-global``).

Per place: ``tf-plus``'s heading seeds (:func:`tfloc.tfplus.matcher.heading_seeds`, the place's
pose as the guess) and its two-level coarse grid (:mod:`tfloc.tfplus.coarse`) on its pooled
distance field; then the coarse candidates of *all* places compete on their coarse score (the
same field and points for every place, so the scores compare), and only the best ``refined``
(at least ``separation`` apart) go through one batched refinement
(:mod:`tfloc.tfplus.refine`) and the selection cost (:mod:`tfloc.tfplus.cost`). Per-place
``localize`` refines ``candidates`` poses of every place, in one call per place.

``tf-plus``'s switches apply (``tf_seed``, ``heading_sweep``, ``grid``, ``refine``,
``refine_to``, ``beam_check``) except ``select="tf"``, which ranks as ``"residual"`` here, and
its tie-break towards the guess (a place is no prior).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from tfloc.core.pose import Pose
from tfloc.core.problem import Problem
from tfloc.maps.grid import GridMap
from tfloc.tfplus.coarse import best_candidates, candidates, lattice
from tfloc.tfplus.cost import scan_cost
from tfloc.tfplus.matcher import TfPlusConfig, heading_seeds
from tfloc.tfplus.refine import refine, refine_to_field
from tfloc.tfplus.view import map_view


def resolve_places(problem: Problem, places: np.ndarray, cfg: TfPlusConfig,
                   refined: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Refined poses ``(K, 3)`` and their selection costs ``(K,)`` (metres²) from the place
    poses ``(P, 3)``, and the number of pose evaluations."""
    m = problem.map
    points = problem.points
    field = map_view(m, cfg.field_resolution, cfg.field_truncation, cfg.wall_thickness)
    coarse = map_view(m, cfg.field_resolution, cfg.field_truncation, cfg.wall_thickness,
                      cfg.grid_step / 2.0 if cfg.coarse_bound else 0.0)
    stride = max(1, len(points) // cfg.coarse_points) if cfg.coarse_points else cfg.scan_stride
    cands, scores, evaluations = [], [], 0
    for place in places:
        guess = dataclasses.replace(problem, initial=Pose.from_array(place))
        heads, _ = heading_seeds(guess, cfg)
        positions = (lattice(m, field, place[:2], cfg.search_radius, cfg.grid_step, cfg.clearance)
                     if cfg.grid else np.empty((0, 2)))
        if len(positions) == 0:
            positions = place[None, :2]
        best, s, rescored = candidates(coarse, points, positions, heads, stride, cfg.shortlist,
                                       cfg.candidates, cfg.separation, cfg.grid_step)
        cands.append(best)
        scores.append(s)
        evaluations += len(positions) * len(heads) + rescored
    poses = best_candidates(np.concatenate(cands), np.concatenate(scores), refined, cfg.separation)
    to = cfg.refine_to if cfg.refine_to != "auto" else ("field" if isinstance(m, GridMap) else "virtual")
    if cfg.refine and to == "field":
        poses = refine_to_field(field, points, poses, cfg.refinement)
    elif cfg.refine:
        poses = refine(m, problem.laser, points, poses, cfg.refinement)
    evaluations += len(poses) * cfg.refinement.iterations * cfg.refine
    cost = scan_cost(m, problem.laser, problem.ranges, poses, cfg.refinement.window,
                     cfg.refinement.inlier_distance, cfg.beam_check,
                     field if cfg.select != "virtual" else None)
    return poses, cost, evaluations
