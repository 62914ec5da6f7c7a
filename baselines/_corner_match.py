"""Fair corner correspondences without the truth: rigid hypotheses from corner pairs whose lengths
agree, scored by one-to-one (mutual nearest neighbour) inliers. Pure, vectorised numpy."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Hypotheses:
    """Rigid transforms ``b = R(theta) a + t`` proposed by corner pairs, ``(H,)`` and ``(H, 2)``."""

    theta: np.ndarray
    t: np.ndarray


def pair_hypotheses(a: np.ndarray, b: np.ndarray, length_tol: float, min_length: float,
                    max_angle: float, max_shift: float) -> Hypotheses:
    """Every rigid transform mapping an ordered corner pair of ``a`` onto one of ``b`` whose
    lengths agree within ``length_tol`` metres (pairs shorter than ``min_length`` are skipped), with
    rotation within ``±max_angle`` radians and translation within ``max_shift`` metres."""
    ia, ja = np.nonzero(~np.eye(len(a), dtype=bool))
    ib, jb = np.nonzero(~np.eye(len(b), dtype=bool))
    va, vb = a[ja] - a[ia], b[jb] - b[ib]
    la, lb = np.hypot(va[:, 0], va[:, 1]), np.hypot(vb[:, 0], vb[:, 1])
    keep_a, keep_b = la >= min_length, lb >= min_length
    ia, va, la = ia[keep_a], va[keep_a], la[keep_a]
    ib, vb, lb = ib[keep_b], vb[keep_b], lb[keep_b]
    pa, pb = np.nonzero(np.abs(la[:, None] - lb[None, :]) <= length_tol)
    theta = np.arctan2(vb[pb, 1], vb[pb, 0]) - np.arctan2(va[pa, 1], va[pa, 0])
    theta = (theta + np.pi) % (2 * np.pi) - np.pi
    c, s = np.cos(theta), np.sin(theta)
    # Anchor on the pair midpoints: rotate a's midpoint and move it onto b's midpoint.
    ma = a[ia[pa]] + 0.5 * va[pa]
    mb = b[ib[pb]] + 0.5 * vb[pb]
    t = mb - np.column_stack((c * ma[:, 0] - s * ma[:, 1], s * ma[:, 0] + c * ma[:, 1]))
    ok = (np.abs(theta) <= max_angle) & (np.hypot(t[:, 0], t[:, 1]) <= max_shift)
    return Hypotheses(theta[ok], t[ok])


def transform(theta: np.ndarray, t: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Apply ``(H,)`` rotations and ``(H, 2)`` translations to points ``(N, 2)`` → ``(H, N, 2)``."""
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    x = c * a[None, :, 0] - s * a[None, :, 1] + t[:, None, 0]
    y = s * a[None, :, 0] + c * a[None, :, 1] + t[:, None, 1]
    return np.stack((x, y), axis=-1)


def mutual_inliers(moved: np.ndarray, b: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """One-to-one inliers of ``(H, N, 2)`` moved corners against ``(M, 2)`` corners.

    A pair (i, k) is an inlier when k is i's nearest corner, i is k's nearest, and they lie within
    ``tol`` metres. Returns ``(H, N)`` partner index (−1 = none) and ``(H, N)`` distances.
    """
    d = np.linalg.norm(moved[:, :, None, :] - b[None, None, :, :], axis=-1)  # (H, N, M)
    nn_b = d.argmin(axis=2)  # (H, N)
    nn_a = d.argmin(axis=1)  # (H, M)
    dist = np.take_along_axis(d, nn_b[..., None], axis=2)[..., 0]
    mutual = np.take_along_axis(nn_a, nn_b, axis=1) == np.arange(moved.shape[1])[None, :]
    partner = np.where(mutual & (dist <= tol), nn_b, -1)
    return partner, dist


def best_hypothesis(a: np.ndarray, b: np.ndarray, hyp: Hypotheses, tol: float) -> tuple[int, np.ndarray, np.ndarray]:
    """The hypothesis with the most one-to-one inliers (ties: smallest summed inlier distance).

    Returns its index, the ``(N,)`` partner indices (−1 = none) and the ``(N,)`` distances.
    """
    partner, dist = mutual_inliers(transform(hyp.theta, hyp.t, a), b, tol)
    inl = partner >= 0
    count = inl.sum(axis=1)
    resid = np.where(inl, dist, 0.0).sum(axis=1)
    h = int(np.lexsort((resid, -count))[0])
    return h, partner[h], dist[h]
