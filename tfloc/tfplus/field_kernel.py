"""Compiled kernels of ``tf-plus``'s refinement against the map itself, used on grid maps
(:func:`tfloc.tfplus.refine.refine_to_field`): scan points paired with their cells' nearest map
points and one Gauss–Newton system (:func:`field_pairs_kernel`), the returns' depth behind the
walls' surfaces, the iterations, and the whole refinement with its pruning in one call
(:func:`refine_to_field_kernel`, which the staged matcher and the one-call pipeline both run).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .virtual_kernel import prune_index_kernel, truncated_cost_kernel


@njit(cache=True, nogil=True)
def _to_nearest(field: tuple[np.ndarray, float, float, float, np.ndarray], px: float, py: float,
                c: float, s: float, x: float, y: float) -> tuple[float, float, int, float, float]:
    """The scan point ``(x, y)`` (sensor frame) at the pose ``(px, py)`` turned by ``(c, s)``,
    against ``field`` = (nearest, origin x, origin y, 1 / resolution, map points) (see
    :func:`field_pairs_kernel`): its offset from the sensor ``(ox, oy)`` (world axes), the index
    ``j`` of its cell's nearest map point (-1: none; cell indices clipped into the lattice) and its
    offset ``(dx, dy)`` from that point (NaN if none)."""
    nearest, origin_x, origin_y, inv, map_points = field
    ny, nx = nearest.shape
    ox = c * x - s * y
    oy = s * x + c * y
    wx, wy = px + ox, py + oy
    ix = min(max(int(math.floor((wx - origin_x) * inv)), 0), nx - 1)
    iy = min(max(int(math.floor((wy - origin_y) * inv)), 0), ny - 1)
    j = nearest[iy, ix]
    if j < 0:
        return ox, oy, j, np.nan, np.nan
    return ox, oy, j, wx - map_points[j, 0], wy - map_points[j, 1]


@njit(cache=True, nogil=True)
def field_pairs_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       map_points: np.ndarray, map_normals: np.ndarray, face_plus: np.ndarray,
                       face_minus: np.ndarray, points: np.ndarray, poses: np.ndarray,
                       offsets: np.ndarray, gate: float, slack: float, cell_weight: float,
                       face_weight: float,
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Point-to-line pairs of scan points with their nearest map points, and one Gauss–Newton system.

    ``nearest`` ``(ny, nx)``: index into the map points ``(N, 2)``, their unit normals ``(N, 2)``
    and the distances ``face_plus``/``face_minus`` ``(N,)`` from each point to its wall's surface
    along ``±normal`` of each cell's nearest map point (a
    :class:`~tfloc.tfplus.view.DistanceField`). ``points`` ``(M, 2)``: the scan (sensor frame);
    ``poses`` ``(K, 3)`` world poses, ``offsets`` ``(K,)`` how far (metres) the returns lie behind
    the walls' surfaces. Each world point ``w`` is paired with the map point ``q`` of its cell if
    ``|w − q| ≤ gate``. Its residual is ``n·(w − q)`` (metres), or with ``use_faces``, with ``n``
    turned to face the sensor, ``n·(w − q) − face + offset`` (``face`` the distance to the
    surface on the sensor's side).

    Returns, per pose, the normal equations ``H`` ``(K, 4, 4)`` and ``g`` ``(K, 4)`` in the
    additive parameters ``(x, y, θ, offset)`` (the offset's column is zero without faces), the
    residuals ``(K, M)`` (NaN: unpaired), and the ranking residual ``max(|n·(w − q)|, |w − q| −
    slack)`` ``(K, M)`` of every point, paired or not (the second term keeps a point beyond the
    end of a wall, on the wall's line, from counting as on it).
    """
    k_n, m = poses.shape[0], points.shape[0]
    hh = np.zeros((k_n, 4, 4))
    gg = np.zeros((k_n, 4))
    res = np.full((k_n, m), np.nan)
    rank = np.empty((k_n, m))
    field = (nearest, origin_x, origin_y, 1.0 / resolution, map_points)
    near = np.empty(m, dtype=np.int64)     # each point's nearest map point (-1: none) ...
    geo = np.empty((m, 4))                 # ... its offset from the sensor and from that point
    faces = face_weight > 0.0
    cw, fw = cell_weight, face_weight
    for k in range(k_n):
        px, py = poses[k, 0], poses[k, 1]
        c, s = math.cos(poses[k, 2]), math.sin(poses[k, 2])
        offset = offsets[k]
        # the sums in registers, each in point order (cell term, then face term) as it was in
        # hh/gg; a weighted product (w·a)·b is not (w·b)·a, so all 16 of H
        h00 = h01 = h02 = h03 = h10 = h11 = h12 = h13 = 0.0
        h20 = h21 = h22 = h23 = h30 = h31 = h32 = h33 = 0.0
        g0 = g1 = g2 = g3 = 0.0
        # first every point's nearest map point (independent look-ups the processor overlaps),
        # then the pairs, whose branches would otherwise wait on two dependent look-ups each
        for i in range(m):
            ox, oy, j, dx, dy = _to_nearest(field, px, py, c, s, points[i, 0], points[i, 1])
            near[i] = j
            geo[i, 0], geo[i, 1], geo[i, 2], geo[i, 3] = ox, oy, dx, dy
        for i in range(m):
            j = near[i]
            ox, oy, dx, dy = geo[i, 0], geo[i, 1], geo[i, 2], geo[i, 3]
            if j < 0:
                rank[k, i] = np.inf
                continue
            nxj, nyj = map_normals[j, 0], map_normals[j, 1]
            r = nxj * dx + nyj * dy
            dist = math.sqrt(dx * dx + dy * dy)
            rank[k, i] = max(abs(r), dist - slack)
            if dist > gate:
                continue
            res[k, i] = r
            a0, a1, a2 = nxj, nyj, -nxj * oy + nyj * ox          # the Jacobian (x, y, θ)
            w0, w1, w2 = cw * a0, cw * a1, cw * a2
            g0 += w0 * r
            g1 += w1 * r
            g2 += w2 * r
            h00 += w0 * a0
            h01 += w0 * a1
            h02 += w0 * a2
            h10 += w1 * a0
            h11 += w1 * a1
            h12 += w1 * a2
            h20 += w2 * a0
            h21 += w2 * a1
            h22 += w2 * a2
            if faces:
                if nxj * ox + nyj * oy > 0.0:          # the normal faces away from the sensor
                    nxj, nyj, rf = -nxj, -nyj, -r - face_minus[j]
                else:
                    rf = r - face_plus[j]
                rf += offset
                a0, a1, a2, a3 = nxj, nyj, -nxj * oy + nyj * ox, 1.0   # (x, y, θ, offset)
                w0, w1, w2, w3 = fw * a0, fw * a1, fw * a2, fw * a3
                g0 += w0 * rf
                g1 += w1 * rf
                g2 += w2 * rf
                g3 += w3 * rf
                h00 += w0 * a0
                h01 += w0 * a1
                h02 += w0 * a2
                h03 += w0 * a3
                h10 += w1 * a0
                h11 += w1 * a1
                h12 += w1 * a2
                h13 += w1 * a3
                h20 += w2 * a0
                h21 += w2 * a1
                h22 += w2 * a2
                h23 += w2 * a3
                h30 += w3 * a0
                h31 += w3 * a1
                h32 += w3 * a2
                h33 += w3 * a3
        hh[k, 0, 0], hh[k, 0, 1], hh[k, 0, 2], hh[k, 0, 3] = h00, h01, h02, h03
        hh[k, 1, 0], hh[k, 1, 1], hh[k, 1, 2], hh[k, 1, 3] = h10, h11, h12, h13
        hh[k, 2, 0], hh[k, 2, 1], hh[k, 2, 2], hh[k, 2, 3] = h20, h21, h22, h23
        hh[k, 3, 0], hh[k, 3, 1], hh[k, 3, 2], hh[k, 3, 3] = h30, h31, h32, h33
        gg[k, 0], gg[k, 1], gg[k, 2], gg[k, 3] = g0, g1, g2, g3
    return hh, gg, res, rank


@njit(cache=True, nogil=True)
def face_depths_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                       map_points: np.ndarray, map_normals: np.ndarray, face_plus: np.ndarray,
                       face_minus: np.ndarray, points: np.ndarray, poses: np.ndarray,
                       gate: float) -> np.ndarray:
    """How deep (metres) each scan point lies behind its wall's surface on the sensor's side
    (``(K, M)``; NaN if its nearest map point is farther than ``gate``); see
    :func:`field_pairs_kernel` for the arguments."""
    k_n, m = poses.shape[0], points.shape[0]
    out = np.full((k_n, m), np.nan)
    field = (nearest, origin_x, origin_y, 1.0 / resolution, map_points)
    for k in range(k_n):
        px, py = poses[k, 0], poses[k, 1]
        c, s = math.cos(poses[k, 2]), math.sin(poses[k, 2])
        for i in range(m):
            ox, oy, j, dx, dy = _to_nearest(field, px, py, c, s, points[i, 0], points[i, 1])
            if j < 0 or dx * dx + dy * dy > gate * gate:
                continue
            r = map_normals[j, 0] * dx + map_normals[j, 1] * dy
            if map_normals[j, 0] * ox + map_normals[j, 1] * oy > 0.0:
                out[k, i] = r + face_minus[j]
            else:
                out[k, i] = face_plus[j] - r
    return out


@njit(cache=True, nogil=True)
def refine_field_kernel(nearest: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                        map_points: np.ndarray, map_normals: np.ndarray, face_plus: np.ndarray,
                        face_minus: np.ndarray, points: np.ndarray, poses: np.ndarray,
                        offsets: np.ndarray, gates: np.ndarray, inner: int, offset_gate: float,
                        faces: bool, face_weight: float, cell_weight: float, damping: float,
                        offset_weight: float, offset_prior: float, max_depth: float,
                        started: bool) -> bool:
    """Gauss–Newton iterations of :func:`tfloc.tfplus.refine.refine_to_field`, one per gate of ``gates``
    × ``inner``, on ``poses`` ``(K, 3)`` and ``offsets`` ``(K,)`` in place (see there and
    :func:`field_pairs_kernel`). Returns whether the depth offsets have been started."""
    k_n = poses.shape[0]
    eye = np.eye(4)
    for it in range(gates.shape[0]):
        gate = gates[it]
        late = faces and gate <= offset_gate
        if late and not started:
            started = True
            d = face_depths_kernel(nearest, origin_x, origin_y, resolution, map_points, map_normals,
                                   face_plus, face_minus, points, poses, gate)
            for k in range(k_n):
                v = d[k][~np.isnan(d[k])]
                offsets[k] = min(max(np.median(v), 0.0), max_depth) if v.size else offset_prior
        fw = face_weight if late else 0.0
        cw = cell_weight if late else 1.0
        for _ in range(inner):
            h, g, r, _ = field_pairs_kernel(nearest, origin_x, origin_y, resolution, map_points,
                                            map_normals, face_plus, face_minus, points, poses,
                                            offsets, gate, resolution, cw, fw)
            for k in range(k_n):
                paired = 0
                for i in range(r.shape[1]):
                    if not math.isnan(r[k, i]):
                        paired += 1
                if paired < 3:
                    continue
                hk = h[k] + damping * eye
                gk = g[k].copy()
                hk[3, 3] += offset_weight
                gk[3] += offset_weight * (offsets[k] - offset_prior)
                step = np.linalg.solve(hk, gk)
                poses[k, 0] -= step[0]
                poses[k, 1] -= step[1]
                poses[k, 2] = (poses[k, 2] - step[2] + np.pi) % (2 * np.pi) - np.pi
                offsets[k] -= step[3]
    return started


@njit(cache=True, nogil=True)
def refine_to_field_kernel(view: tuple, points: np.ndarray, poses: np.ndarray, inlier: float,
                           refine: tuple) -> np.ndarray:
    """:func:`tfloc.tfplus.refine.refine_to_field` in one call: ``(K, 3)`` world ``poses`` refined
    so the scan ``points`` ``(M, 2)`` lie on the map ``view`` = (nearest, origin x, origin y,
    resolution, map points, map normals); ``refine`` is
    :func:`~tfloc.tfplus.refine.field_refinement`'s tuple, ``inlier`` the truncation (metres) of
    the pruning's residual. The iterations up to ``prune_after``
    (:func:`refine_field_kernel`), the pruning to the ``keep`` best by
    truncated residual (:func:`field_pairs_kernel` at the last gate), the
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
