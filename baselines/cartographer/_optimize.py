"""Cartographer's 2D sparse pose optimisation (``optimization_problem_2d.cc``, ``spa_cost_function_2d.h``)
over the localization trajectory's nodes and submaps, the frozen submaps held constant.

Every residual block relates a *start* pose (a submap's, or the first of two consecutive nodes)
to an *end* pose (a node's) through a measured relative pose ``z`` (in the start's frame):

    h = R(θ_s)ᵀ·(t_e − t_s), θ_e − θ_s;   residual = (w_t·(z_xy − h_xy), w_r·wrap(z_θ − h_θ))

Blocks: a node in a local submap (intra-submap constraints, ``matcher_*_weight``), a node in a
frozen submap (the constraint builder's answers, ``loop_closure_*_weight``, under Ceres'
``HuberLoss(huber_scale)``), consecutive nodes' local SLAM poses (``local_slam_pose_*_weight``)
and their odometry (``odometry_*_weight``). The Huber loss acts on a block's squared norm s as
Ceres applies it, ρ(s) = s for s ≤ a², else 2a√s − a²: here by scaling the block's residual by
√(ρ(s)/s) (its Jacobian by the exact derivative), so that scipy's squared sum is Ceres' cost.
Solved by ``scipy.optimize.least_squares`` (trust region, sparse Jacobian, LSMR steps) with at most
``max_num_iterations`` evaluations and Ceres' default tolerances. Metres, radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.sparse import csr_matrix

from tfloc.core.pose import wrap_angle


@dataclass(frozen=True)
class Blocks:
    """Residual blocks, ``B`` of them: ``start`` ``(B,)`` variable index or −1 for a constant start
    (then ``start_pose`` ``(B, 3)`` is used), ``end`` ``(B,)`` variable index, measured ``z``
    ``(B, 3)``, weights ``w_t``/``w_r`` ``(B,)``, ``robust`` ``(B,)`` (Huber on the block)."""

    start: np.ndarray
    start_pose: np.ndarray
    end: np.ndarray
    z: np.ndarray
    w_t: np.ndarray
    w_r: np.ndarray
    robust: np.ndarray


def _errors(x: np.ndarray, b: Blocks):  # noqa: ANN202 - arrays
    S = np.where(b.start[:, None] >= 0, x[np.maximum(b.start, 0)], b.start_pose)
    E = x[b.end]
    dx, dy = E[:, 0] - S[:, 0], E[:, 1] - S[:, 1]
    c, s = np.cos(S[:, 2]), np.sin(S[:, 2])
    h = np.column_stack((c * dx + s * dy, -s * dx + c * dy, E[:, 2] - S[:, 2]))
    e = b.z - h
    e[:, 2] = wrap_angle(e[:, 2])
    w = np.column_stack((b.w_t, b.w_t, b.w_r))
    # d h / d end and d h / d start, (B, 3 components, 3 coordinates)
    dE = np.zeros((len(c), 3, 3))
    dE[:, 0, 0], dE[:, 0, 1], dE[:, 1, 0], dE[:, 1, 1], dE[:, 2, 2] = c, s, -s, c, 1.0
    dS = -dE
    dS[:, 0, 2] = -s * dx + c * dy
    dS[:, 1, 2] = -c * dx - s * dy
    return w * e, -w[:, :, None] * dE, -w[:, :, None] * dS


def _huber(r: np.ndarray, robust: np.ndarray, a: float) -> np.ndarray:
    """Per block (B, 3, 3) the matrix M with r̃ = M·r's Jacobian M·J, and scales g with r̃ = g·r."""
    s = np.einsum("bi,bi->b", r, r)
    out = robust & (s > a * a)
    g = np.ones(len(r))
    gp = np.zeros(len(r))
    so = s[out]
    g[out] = np.sqrt(2.0 * a / np.sqrt(so) - a * a / so)
    gp[out] = (-a * so ** -1.5 + a * a / so ** 2) / (2.0 * g[out])
    M = g[:, None, None] * np.eye(3)[None] + 2.0 * gp[:, None, None] * r[:, :, None] * r[:, None, :]
    return g, M


def solve(x0: np.ndarray, b: Blocks, huber_scale: float, max_num_iterations: int) -> tuple[np.ndarray, object]:
    """The optimised variable poses ``(V, 3)`` from ``x0`` ``(V, 3)``, and scipy's result."""
    V, B = len(x0), len(b.end)
    rows = np.repeat(np.arange(3 * B).reshape(B, 3), 3, axis=1)  # (B, 9)
    end_cols = (3 * b.end[:, None] + np.tile(np.arange(3), 3)[None, :])
    start_cols = (3 * np.maximum(b.start, 0)[:, None] + np.tile(np.arange(3), 3)[None, :])
    has_start = b.start >= 0

    def fun(v: np.ndarray) -> np.ndarray:
        r, _, _ = _errors(v.reshape(V, 3), b)
        g, _ = _huber(r, b.robust, huber_scale)
        return (g[:, None] * r).ravel()

    def jac(v: np.ndarray) -> csr_matrix:
        r, jE, jS = _errors(v.reshape(V, 3), b)
        _, M = _huber(r, b.robust, huber_scale)
        jE, jS = M @ jE, M @ jS
        data = np.concatenate((jE.reshape(B, 9).ravel(), jS[has_start].reshape(-1, 9).ravel()))
        rr = np.concatenate((rows.ravel(), rows[has_start].ravel()))
        cc = np.concatenate((end_cols.ravel(), start_cols[has_start].ravel()))
        return csr_matrix((data, (rr, cc)), shape=(3 * B, 3 * V))

    sol = least_squares(fun, x0.ravel(), jac=jac, method="trf", tr_solver="lsmr", x_scale="jac",
                        ftol=1e-6, xtol=1e-8, gtol=1e-10, max_nfev=max_num_iterations)
    return sol.x.reshape(V, 3), sol
