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
Solved as Ceres solves it, Levenberg–Marquardt on the sparse normal equations
(:func:`_levenberg_marquardt`, scipy's sparse LU for the step), at most ``max_num_iterations``
iterations. (``scipy.optimize.least_squares`` with LSMR steps stops early: the pose graph's
weights span 1e2–1e5, and its inexact steps barely move the trajectory as a whole, the one
direction the map's constraints decide.) Metres, radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix, diags
from scipy.sparse.linalg import spsolve

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


def _levenberg_marquardt(f, x0: np.ndarray, max_num_iterations: int) -> tuple[np.ndarray, dict]:
    """Ceres' Levenberg–Marquardt (``levenberg_marquardt_strategy.cc``, SPARSE_NORMAL_CHOLESKY):
    steps from (JᵀJ + diag(JᵀJ)/μ)·δ = −Jᵀr solved exactly (a sparse LU), μ the trust region
    radius (initial 1e4; ×1/max(⅓, 1 − (2ρ − 1)³) on success, ÷ a doubling factor on failure);
    Ceres' tolerances (function 1e-6, gradient 1e-10, parameter 1e-8)."""
    x = x0.copy()
    r, J = f(x)
    cost = 0.5 * float(r @ r)
    radius, decrease = 1e4, 2.0
    it = 0
    for it in range(1, max_num_iterations + 1):  # noqa: B007 - reported
        g = J.T @ r
        if np.max(np.abs(g), initial=0.0) <= 1e-10:
            break
        H = (J.T @ J).tocsc()
        D = np.clip(H.diagonal(), 1e-6, 1e32)
        step = -spsolve((H + diags(D / radius)).tocsc(), g)
        x_new = x + step
        r_new, J_new = f(x_new)
        cost_new = 0.5 * float(r_new @ r_new)
        model = -(float(g @ step) + 0.5 * float(step @ (H @ step)))
        rho = (cost - cost_new) / model if model > 0 else -1.0
        if rho > 1e-3:
            done = (abs(cost - cost_new) <= 1e-6 * cost
                    or np.linalg.norm(step) <= 1e-8 * (np.linalg.norm(x) + 1e-8))
            x, r, J, cost = x_new, r_new, J_new, cost_new
            radius, decrease = radius / max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), 2.0
            if done:
                break
        else:
            radius, decrease = radius / decrease, 2.0 * decrease
    return x, {"cost": cost, "iterations": it}


def solve(x0: np.ndarray, b: Blocks, huber_scale: float, max_num_iterations: int) -> tuple[np.ndarray, dict]:
    """The optimised variable poses ``(V, 3)`` from ``x0`` ``(V, 3)``, and the final cost and
    iterations."""
    V, B = len(x0), len(b.end)
    rows = np.repeat(np.arange(3 * B).reshape(B, 3), 3, axis=1)  # (B, 9)
    end_cols = (3 * b.end[:, None] + np.tile(np.arange(3), 3)[None, :])
    start_cols = (3 * np.maximum(b.start, 0)[:, None] + np.tile(np.arange(3), 3)[None, :])
    has_start = b.start >= 0

    def f(v: np.ndarray) -> tuple[np.ndarray, csr_matrix]:
        r, jE, jS = _errors(v.reshape(V, 3), b)
        g, M = _huber(r, b.robust, huber_scale)
        jE, jS = M @ jE, M @ jS
        data = np.concatenate((jE.reshape(B, 9).ravel(), jS[has_start].reshape(-1, 9).ravel()))
        rr = np.concatenate((rows.ravel(), rows[has_start].ravel()))
        cc = np.concatenate((end_cols.ravel(), start_cols[has_start].ravel()))
        return (g[:, None] * r).ravel(), csr_matrix((data, (rr, cc)), shape=(3 * B, 3 * V))

    x, info = _levenberg_marquardt(f, x0.ravel().astype(float), max_num_iterations)
    return x.reshape(V, 3), info
