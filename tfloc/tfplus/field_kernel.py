"""The refinement against the map (:func:`tfloc.tfplus.refine.refine_to_field`, used on grid maps)
in one compiled call: its Gauss–Newton runs before and after the pruning, and the pruning. Both the
staged matcher and the one-call pipeline (:mod:`tfloc.tfplus.pipeline`) run it."""

from __future__ import annotations

import numpy as np
from numba import njit

from .kernels import field_pairs_kernel, refine_field_kernel
from .virtual_kernel import prune_index_kernel, truncated_cost_kernel


@njit(cache=True, nogil=True)
def refine_to_field_kernel(view: tuple, points: np.ndarray, poses: np.ndarray, inlier: float,
                           refine: tuple) -> np.ndarray:
    """:func:`tfloc.tfplus.refine.refine_to_field` in one call: ``(K, 3)`` world ``poses`` refined
    so the scan ``points`` ``(M, 2)`` lie on the map ``view`` = (nearest, origin x, origin y,
    resolution, map points, map normals); ``refine`` is
    :func:`~tfloc.tfplus.refine.field_refinement`'s tuple, ``inlier`` the truncation (metres) of
    the pruning's residual. The iterations up to ``prune_after``
    (:func:`~tfloc.tfplus.kernels.refine_field_kernel`), the pruning to the ``keep`` best by
    truncated residual (:func:`~tfloc.tfplus.kernels.field_pairs_kernel` at the last gate), the
    rest of the iterations (one per gate)."""
    nearest, fx, fy, fres, map_points, map_normals = view
    (gates, inner, damping, prune_after, keep, faces, field_faces, face_plus, face_minus,
     offset_gate, face_weight, cell_weight, offset_weight, offset_prior, max_depth) = refine
    iterations = gates.shape[0]
    poses = poses.copy()
    offsets = np.full(poses.shape[0], offset_prior)
    cut = prune_after if 0 < prune_after < iterations else iterations
    started = False
    for part_no in range(2):
        part = gates[:cut] if part_no == 0 else gates[cut:]
        if part.shape[0] == 0:
            continue
        started = refine_field_kernel(nearest, fx, fy, fres, map_points, map_normals, face_plus,
                                      face_minus, points, poses, offsets,
                                      np.ascontiguousarray(part), inner, offset_gate, faces,
                                      face_weight, cell_weight, damping, offset_weight,
                                      offset_prior, max_depth, started)
        if part_no == 0 and cut < iterations and poses.shape[0] > keep:
            late = faces and part[-1] <= offset_gate
            fw = face_weight if late else 0.0
            cw = cell_weight if late else 1.0
            with_faces = field_faces and fw > 0
            _, _, r, _ = field_pairs_kernel(nearest, fx, fy, fres, map_points, map_normals,
                                            face_plus, face_minus, points, poses, offsets,
                                            part[-1], fres, cw if with_faces else 1.0,
                                            fw if with_faces else 0.0)
            kept = prune_index_kernel(poses, truncated_cost_kernel(r, inlier), keep, 0.05)
            poses, offsets = poses[kept], offsets[kept]
    return poses
