"""Fair corner correspondences without the truth: rigid hypotheses from corner pairs whose lengths
agree, scored by one-to-one (mutual nearest neighbour) inliers. Pure functions (numpy; the loops
over candidate pairs and hypotheses are numba kernels in :mod:`tfloc.baselines._corner_kernels`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._corner_kernels import adaptive_search, inlier_counts, pair_transforms


@dataclass(frozen=True)
class Hypotheses:
    """Rigid transforms ``b = R(theta) a + t`` proposed by corner pairs, ``(H,)`` and ``(H, 2)``."""

    theta: np.ndarray
    t: np.ndarray


def _pairs(p: np.ndarray, ordered: bool, min_length: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Corner pairs (i, j) of ``p`` at least ``min_length`` metres long: every ordered pair, or
    each unordered pair once (i < j). Returns their lengths, directions (radians) and midpoints."""
    i, j = np.nonzero(~np.eye(len(p), dtype=bool)) if ordered else np.triu_indices(len(p), 1)
    v = p[j] - p[i]
    length = np.hypot(v[:, 0], v[:, 1])
    keep = length >= min_length
    v, length = v[keep], length[keep]
    return length, np.arctan2(v[:, 1], v[:, 0]), p[i[keep]] + 0.5 * v


def pair_hypotheses(a: np.ndarray, b: np.ndarray, length_tol: float, min_length: float,
                    max_angle: float, max_shift: float, max_hypotheses: int = 20000) -> Hypotheses:
    """Every rigid transform mapping a corner pair of ``a`` onto an ordered corner pair of ``b``
    whose lengths agree within ``length_tol`` metres (pairs shorter than ``min_length`` are
    skipped), with rotation within ``±max_angle`` radians and translation within ``max_shift``
    metres. The transform is anchored on the pair midpoints (a's midpoint, rotated, lands on b's).

    Each pair of ``a`` is taken once (i < j): the reversed pair with the reversed pair of ``b``
    gives the very same transform, so ordered pairs on both sides would score every hypothesis
    twice. When more than ``max_hypotheses`` survive, an evenly strided, deterministic subset of
    them (in a-pair order, then b-pair length order) is kept, so the cost stays bounded."""
    la, anga, ma = _pairs(np.asarray(a, dtype=float), False, min_length)
    lb, angb, mb = _pairs(np.asarray(b, dtype=float), True, min_length)
    order = np.argsort(lb, kind="stable")
    theta, t, _ = pair_transforms(la, anga, ma, lb[order], angb[order], mb[order],
                                  float(length_tol), float(max_angle), float(max_shift))
    if theta.size > max_hypotheses:
        keep = np.linspace(0, theta.size - 1, max_hypotheses).astype(int)
        theta, t = theta[keep], t[keep]
    return Hypotheses(theta, t)


def transform(theta: np.ndarray, t: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Apply ``(H,)`` rotations and ``(H, 2)`` translations to points ``(N, 2)`` → ``(H, N, 2)``."""
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    ax, ay = a[None, :, 0], a[None, :, 1]
    x = c * ax - s * ay + t[:, None, 0]
    y = s * ax + c * ay + t[:, None, 1]
    return np.stack((x, y), axis=-1)


def mutual_inliers(theta: np.ndarray, t: np.ndarray, a: np.ndarray, b: np.ndarray,
                   tol: float) -> tuple[np.ndarray, np.ndarray]:
    """One-to-one inliers of corners ``a`` moved by each of ``(H,)`` rigid transforms against ``b``.

    A pair (i, k) is an inlier when k is i's nearest corner, i is k's nearest, and they lie within
    ``tol`` metres (ties go to the lower index, as in :func:`inlier_counts`). Builds the
    ``(H, N, M)`` distance array: meant for a few hypotheses (scoring many is
    :func:`best_hypothesis`'s job). Returns ``(H, N)`` partner index (−1 = none) and ``(H, N)``
    distances to the nearest corner of ``b``.
    """
    moved = transform(np.asarray(theta, dtype=float), np.asarray(t, dtype=float), a)   # (H, N, 2)
    d = np.linalg.norm(moved[:, :, None, :] - b[None, None, :, :], axis=-1)            # (H, N, M)
    nn_b, nn_a = d.argmin(axis=2), d.argmin(axis=1)                                    # (H, N), (H, M)
    dist = np.take_along_axis(d, nn_b[:, :, None], axis=2)[:, :, 0]
    mutual = np.take_along_axis(nn_a, nn_b, axis=1) == np.arange(a.shape[0])[None, :]
    return np.where(mutual & (dist <= tol), nn_b, -1), dist


def best_hypothesis(a: np.ndarray, b: np.ndarray, hyp: Hypotheses, tol: float) -> tuple[int, np.ndarray, np.ndarray]:
    """The hypothesis with the most one-to-one inliers (ties: smallest summed inlier distance,
    then the first).

    Returns its index, the ``(N,)`` partner indices (−1 = none) and the ``(N,)`` distances.
    """
    a, b = np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(b, dtype=float)
    count, resid = inlier_counts(hyp.theta, np.ascontiguousarray(hyp.t), a, b, float(tol))
    h = int(np.lexsort((resid, -count))[0])
    partner, dist = mutual_inliers(hyp.theta[h:h + 1], hyp.t[h:h + 1], a, b, tol)
    return h, partner[0], dist[0]


@dataclass(frozen=True)
class Search:
    """The best rigid transform ``b ≈ R(theta) a + t`` of :func:`search_hypotheses` (radians,
    metres), its one-to-one inliers, and what the search cost: transforms scored, pairs of ``a``
    drawn, of ``pairs`` in all."""

    theta: float
    t: np.ndarray
    inliers: int
    scored: int
    drawn: int
    pairs: int


def search_hypotheses(a: np.ndarray, b: np.ndarray, length_tol: float, min_length: float, max_angle: float,
                      max_shift: float, tol: float, confidence: float, max_hypotheses: int,
                      seed: int = 0) -> Search | None:
    """The hypotheses of :func:`pair_hypotheses`, scored as :func:`best_hypothesis` does, but
    drawn pair by pair of ``a`` in a seeded random order and stopped as adaptive RANSAC does: once
    a pair supporting the best match so far would have been drawn with probability
    ``confidence`` (``confidence`` = 1: every pair), or after ``max_hypotheses`` scored transforms.
    ``None`` when no transform lies in the window."""
    a, b = np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(b, dtype=float)
    la, anga, ma = _pairs(a, False, min_length)
    lb, angb, mb = _pairs(b, True, min_length)
    if la.size == 0 or lb.size == 0:
        return None
    order = np.argsort(lb, kind="stable")
    draw = np.random.default_rng(seed).permutation(la.size)
    theta, tx, ty, inliers, scored, drawn = adaptive_search(
        a, b, la, anga, np.ascontiguousarray(ma), draw, lb[order], angb[order], np.ascontiguousarray(mb[order]),
        float(min_length), float(length_tol), float(max_angle), float(max_shift), float(tol),
        float(confidence), int(max_hypotheses))
    if scored == 0:
        return None
    return Search(float(theta), np.array([tx, ty]), int(inliers), int(scored), int(drawn), int(la.size))
