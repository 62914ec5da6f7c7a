"""Fair corner correspondences without the truth: rigid hypotheses from corner pairs whose lengths
agree, scored by one-to-one (mutual nearest neighbour) inliers. Pure functions (numpy, scipy k-d trees)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from tfloc.core.pose import wrap_angle


@dataclass(frozen=True)
class Hypotheses:
    """Rigid transforms ``b = R(theta) a + t`` proposed by corner pairs, ``(H,)`` and ``(H, 2)``."""

    theta: np.ndarray
    t: np.ndarray


def _length_matches(la: np.ndarray, lb: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """All index pairs (i, j) with ``|la[i] − lb[j]| ≤ tol``, found by a sorted window: memory
    grows with the number of matches, not with ``len(la) · len(lb)``."""
    order = np.argsort(lb, kind="stable")
    sb = lb[order]
    lo = np.searchsorted(sb, la - tol, side="left")
    hi = np.searchsorted(sb, la + tol, side="right")
    counts = hi - lo
    pa = np.repeat(np.arange(len(la)), counts)
    starts = np.repeat(np.cumsum(counts) - counts, counts)
    pb = order[np.repeat(lo, counts) + (np.arange(pa.size) - starts)]
    keep = np.abs(la[pa] - lb[pb]) <= tol  # exact test (searchsorted works on the same floats)
    return pa[keep], pb[keep]


def pair_hypotheses(a: np.ndarray, b: np.ndarray, length_tol: float, min_length: float,
                    max_angle: float, max_shift: float, max_hypotheses: int = 20000) -> Hypotheses:
    """Every rigid transform mapping an ordered corner pair of ``a`` onto one of ``b`` whose
    lengths agree within ``length_tol`` metres (pairs shorter than ``min_length`` are skipped), with
    rotation within ``±max_angle`` radians and translation within ``max_shift`` metres.

    Real scans can have 100+ corners (10⁴ ordered pairs each side); when more than
    ``max_hypotheses`` survive, an evenly strided, deterministic subset of them is kept, so the
    cost and memory stay bounded."""
    ia, ja = np.nonzero(~np.eye(len(a), dtype=bool))
    ib, jb = np.nonzero(~np.eye(len(b), dtype=bool))
    va, vb = a[ja] - a[ia], b[jb] - b[ib]
    la, lb = np.hypot(va[:, 0], va[:, 1]), np.hypot(vb[:, 0], vb[:, 1])
    keep_a, keep_b = la >= min_length, lb >= min_length
    ia, va, la = ia[keep_a], va[keep_a], la[keep_a]
    ib, vb, lb = ib[keep_b], vb[keep_b], lb[keep_b]
    pa, pb = _length_matches(la, lb, length_tol)
    order = np.lexsort((pb, pa))  # the (a-pair, b-pair) order of the former all-pairs search
    pa, pb = pa[order], pb[order]
    theta = np.arctan2(vb[pb, 1], vb[pb, 0]) - np.arctan2(va[pa, 1], va[pa, 0])
    theta = wrap_angle(theta)
    c, s = np.cos(theta), np.sin(theta)
    # Anchor on the pair midpoints: rotate a's midpoint and move it onto b's midpoint.
    ma = a[ia[pa]] + 0.5 * va[pa]
    mb = b[ib[pb]] + 0.5 * vb[pb]
    t = mb - np.column_stack((c * ma[:, 0] - s * ma[:, 1], s * ma[:, 0] + c * ma[:, 1]))
    ok = np.flatnonzero((np.abs(theta) <= max_angle) & (np.hypot(t[:, 0], t[:, 1]) <= max_shift))
    if ok.size > max_hypotheses:
        ok = ok[np.linspace(0, ok.size - 1, max_hypotheses).astype(int)]
    return Hypotheses(theta[ok], t[ok])


def transform(theta: np.ndarray, t: np.ndarray, a: np.ndarray, batched: bool = False) -> np.ndarray:
    """Apply ``(H,)`` rotations and ``(H, 2)`` translations to points ``(N, 2)`` (or, if
    ``batched``, to per-hypothesis points ``(H, N, 2)``) → ``(H, N, 2)``."""
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    ax, ay = (a[..., 0], a[..., 1]) if batched else (a[None, :, 0], a[None, :, 1])
    x = c * ax - s * ay + t[:, None, 0]
    y = s * ax + c * ay + t[:, None, 1]
    return np.stack((x, y), axis=-1)


def mutual_inliers(theta: np.ndarray, t: np.ndarray, a: np.ndarray, b: np.ndarray,
                   tol: float) -> tuple[np.ndarray, np.ndarray]:
    """One-to-one inliers of corners ``a`` moved by each of ``(H,)`` rigid transforms against ``b``.

    A pair (i, k) is an inlier when k is i's nearest corner, i is k's nearest, and they lie within
    ``tol`` metres. Nearest neighbours come from k-d trees (scipy) on the fixed sets: ``b`` for the
    moved ``a``, and ``a`` for ``b`` moved back by the inverse transform (distances are
    preserved), so the cost is O(H·(N + M)·log) instead of an (H, N, M) distance array.
    Returns ``(H, N)`` partner index (−1 = none) and ``(H, N)`` distances.
    """
    moved = transform(theta, t, a)                                         # (H, N, 2)
    dist, nn_b = cKDTree(b).query(moved.reshape(-1, 2))
    dist, nn_b = dist.reshape(moved.shape[:2]), nn_b.reshape(moved.shape[:2])
    back = transform(-theta, np.zeros_like(t), b[None, :, :] - t[:, None, :], batched=True)
    nn_a = cKDTree(a).query(back.reshape(-1, 2))[1].reshape(back.shape[:2])  # (H, M)
    mutual = np.take_along_axis(nn_a, nn_b, axis=1) == np.arange(a.shape[0])[None, :]
    partner = np.where(mutual & (dist <= tol), nn_b, -1)
    return partner, dist


def best_hypothesis(a: np.ndarray, b: np.ndarray, hyp: Hypotheses, tol: float) -> tuple[int, np.ndarray, np.ndarray]:
    """The hypothesis with the most one-to-one inliers (ties: smallest summed inlier distance).

    Returns its index, the ``(N,)`` partner indices (−1 = none) and the ``(N,)`` distances.
    """
    partner, dist = mutual_inliers(hyp.theta, hyp.t, a, b, tol)
    inl = partner >= 0
    count = inl.sum(axis=1)
    resid = np.where(inl, dist, 0.0).sum(axis=1)
    h = int(np.lexsort((resid, -count))[0])
    return h, partner[h], dist[h]
