# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/pf/pf.c`` (and ``AmclNode::uniformPoseGenerator`` of ``amcl_node.cpp``,
the random-pose function pf.c calls back): Nav2's particle filter. Initialisation, the sensor
update's normalisation and running averages, KLD-sampling resampling with random-pose injection,
and the cluster statistics the published pose comes from. Compiled with numba; a sample set is a
:class:`SampleSet` value, each step makes a new one.

* ``pf_init`` (Gaussian around a pose) and ``pf_init_model`` (Nav2's ``uniformPoseGenerator``:
  a free cell drawn uniformly, the pose at its Nav2 centre, a uniform heading): ``max_samples``
  particles of weight ``1 / max_samples``.
* ``pf_update_sensor``: weights normalised by their sum; ``w_slow``/``w_fast`` follow the mean
  weight (set to it when zero, as Nav2).
* ``pf_update_resample``: particles drawn one by one (with probability ``max(0, 1 − w_fast /
  w_slow)`` a random pose, else a copy drawn from the weights) into a fresh kd-tree until the
  count exceeds ``pf_resample_limit(k)`` of its ``k`` bins (Fox's KLD bound) or reaches
  ``max_samples``; the averages reset after an injection; weights uniform.
* ``pf_cluster_stats``: per cluster of the kd-tree (:mod:`.pf_kdtree`) and for the whole set:
  weight, mean (heading by its mean cosine and sine) and covariance (x, y, and ``−2 ln R`` for the
  heading, R the unnormalised resultant length, as pf.c).

Departure: the weighted draw finds the sample by bisection of the cumulative weights (the same
sample as Nav2's linear scan, ``O(log n)`` instead of ``O(n)``); a draw beyond the last cumulative
weight (rounding; undefined in Nav2) takes the last sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from . import pf_kdtree as kd
from .pf_pdf import drand48, gaussian_samples


@dataclass(frozen=True, eq=False)
class SampleSet:
    """One of pf.c's sample sets and the statistics of its last clustering (metres, radians).

    Attributes:
        poses: ``(n, 3)`` particles (heading not wrapped).
        weights: ``(n,)`` weights (they sum to 1 after each sensor update and resampling).
        bins: kd-tree bins with samples (KLD sampling's ``k``).
        cluster_count, cluster_weight: ``(c,)`` samples and weight of each cluster.
        cluster_mean, cluster_cov: ``(c, 3)``, ``(c, 3, 3)``.
        mean, cov: ``(3,)``, ``(3, 3)`` of the whole set (the covariance Nav2 publishes).
        converged: ``pf_update_converged``: every particle within 0.5 m (x and y) of the mean.
    """

    poses: np.ndarray
    weights: np.ndarray
    bins: int
    cluster_count: np.ndarray
    cluster_weight: np.ndarray
    cluster_mean: np.ndarray
    cluster_cov: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    converged: bool = False

    @property
    def count(self) -> int:
        return int(self.poses.shape[0])

    def heaviest(self) -> int:
        """``AmclNode::getMaxWeightHyp``: the first cluster of the largest positive weight, or -1."""
        w = self.cluster_weight
        ok = w > 0.0
        if not ok.any():
            return -1
        return int(np.argmax(np.where(ok, w, -np.inf)))


@njit(cache=True, nogil=True)
def resample_limit(k: int, min_samples: int, max_samples: int, pop_err: float, pop_z: float) -> int:
    """``pf_resample_limit``: samples needed for ``k`` occupied bins (Fox 2003), clamped."""
    if k <= 1:
        return max_samples
    a = 1.0
    b = 2 / (9 * (np.float64(k) - 1))
    c = math.sqrt(2 / (9 * (np.float64(k) - 1))) * pop_z
    x = a - b + c
    n = np.ceil((k - 1) / (2 * pop_err) * x * x * x)  # a float: C's int cast of a huge value is undefined
    if n < min_samples:
        return min_samples
    if n > max_samples:
        return max_samples
    return int(n)


@njit(cache=True, nogil=True, error_model="numpy")
def _cluster_stats(tree, poses: np.ndarray, weights: np.ndarray):  # noqa: ANN202 - a tuple (SampleSet's fields)
    """``pf_cluster_stats`` of the samples in ``tree``."""
    table = kd.leaf_table(tree)
    n_clusters = kd.cluster(tree, table)
    count = np.zeros(n_clusters, dtype=np.int64)
    cw = np.zeros(n_clusters)
    cm = np.zeros((n_clusters, 4))
    cc = np.zeros((n_clusters, 2, 2))
    m = np.zeros(4)
    c = np.zeros((2, 2))
    weight = 0.0
    for i in range(poses.shape[0]):
        cidx = kd.cluster_of(tree, table, poses[i])
        if cidx < 0:
            continue
        w = weights[i]
        count[cidx] += 1
        cw[cidx] += w
        weight += w
        cs = math.cos(poses[i, 2])
        sn = math.sin(poses[i, 2])
        cm[cidx, 0] += w * poses[i, 0]
        cm[cidx, 1] += w * poses[i, 1]
        cm[cidx, 2] += w * cs
        cm[cidx, 3] += w * sn
        m[0] += w * poses[i, 0]
        m[1] += w * poses[i, 1]
        m[2] += w * cs
        m[3] += w * sn
        for j in range(2):
            for k in range(2):
                cc[cidx, j, k] += w * poses[i, j] * poses[i, k]
                c[j, k] += w * poses[i, j] * poses[i, k]
    cmean = np.zeros((n_clusters, 3))
    ccov = np.zeros((n_clusters, 3, 3))
    for i in range(n_clusters):
        cmean[i, 0] = cm[i, 0] / cw[i]
        cmean[i, 1] = cm[i, 1] / cw[i]
        cmean[i, 2] = math.atan2(cm[i, 3], cm[i, 2])
        for j in range(2):
            for k in range(2):
                ccov[i, j, k] = cc[i, j, k] / cw[i] - cmean[i, j] * cmean[i, k]
        ccov[i, 2, 2] = -2 * math.log(math.sqrt(cm[i, 2] * cm[i, 2] + cm[i, 3] * cm[i, 3]))
    mean = np.zeros(3)
    cov = np.zeros((3, 3))
    mean[0] = m[0] / weight
    mean[1] = m[1] / weight
    mean[2] = math.atan2(m[3], m[2])
    for j in range(2):
        for k in range(2):
            cov[j, k] = c[j, k] / weight - mean[j] * mean[k]
    cov[2, 2] = -2 * math.log(math.sqrt(m[2] * m[2] + m[3] * m[3]))
    return count, cw, cmean, ccov, mean, cov


@njit(cache=True, nogil=True)
def _converged(poses: np.ndarray) -> bool:
    """``pf_update_converged``: every particle within 0.5 m of the (unweighted) mean in x and y."""
    n = poses.shape[0]
    mx = 0.0
    my = 0.0
    for i in range(n):
        mx += poses[i, 0]
        my += poses[i, 1]
    mx /= n
    my /= n
    for i in range(n):
        if abs(poses[i, 0] - mx) > 0.5 or abs(poses[i, 1] - my) > 0.5:
            return False
    return True


@njit(cache=True, nogil=True)
def uniform_pose(state: np.ndarray, free_cells: np.ndarray, origin_x: float, origin_y: float,
                 scale: float, size_x: int, size_y: int, out: np.ndarray) -> None:
    """``AmclNode::uniformPoseGenerator`` (``NEW_UNIFORM_SAMPLING``): a free cell drawn uniformly,
    the pose at its Nav2 centre (``MAP_WXGX``), heading uniform in [−π, π)."""
    idx = int(drand48(state) * free_cells.shape[0])
    i = free_cells[idx, 0]
    j = free_cells[idx, 1]
    out[0] = origin_x + (i - size_x // 2) * scale
    out[1] = origin_y + (j - size_y // 2) * scale
    out[2] = drand48(state) * 2 * math.pi - math.pi


@njit(cache=True, nogil=True)
def _histogram_stats(poses: np.ndarray, weights: np.ndarray):  # noqa: ANN202 - a tuple (SampleSet's fields)
    """The histogram of ``poses`` (inserted in order with their ``weights``): its bins and the
    cluster statistics."""
    tree = kd.alloc(max(3 * poses.shape[0], 1))
    for i in range(poses.shape[0]):
        kd.insert(tree, poses[i], weights[i])
    return tree[7][2], _cluster_stats(tree, poses, weights)


@njit(cache=True, nogil=True)
def _uniform_poses(state: np.ndarray, free_cells: np.ndarray, origin_x: float, origin_y: float,
                   scale: float, size_x: int, size_y: int, n: int) -> np.ndarray:
    out = np.empty((n, 3))
    for k in range(n):
        uniform_pose(state, free_cells, origin_x, origin_y, scale, size_x, size_y, out[k])
    return out


def _sample_set(poses: np.ndarray, weights: np.ndarray, bins: int, stats, converged: bool) -> SampleSet:
    count, cw, cmean, ccov, mean, cov = stats
    return SampleSet(poses, weights, int(bins), count, cw, cmean, ccov, mean, cov, bool(converged))


def clustered(poses: np.ndarray, weights: np.ndarray, converged: bool = False) -> SampleSet:
    """The :class:`SampleSet` of ``poses`` ``(n, 3)`` and ``weights`` ``(n,)``: histogram and
    cluster statistics as ``pf_init`` computes them."""
    poses = np.ascontiguousarray(poses, dtype=float)
    weights = np.ascontiguousarray(weights, dtype=float)
    bins, stats = _histogram_stats(poses, weights)
    return _sample_set(poses, weights, bins, stats, converged)


def init_gaussian(state: np.ndarray, mean: np.ndarray, cov: np.ndarray, max_samples: int) -> SampleSet:
    """``pf_init``: ``max_samples`` particles drawn from N(``mean``, ``cov``), weights ``1 / max_samples``."""
    poses = gaussian_samples(state, np.asarray(mean, dtype=float), np.asarray(cov, dtype=float), max_samples)
    return clustered(poses, np.full(max_samples, 1.0 / max_samples))


def init_uniform(state: np.ndarray, free_cells: np.ndarray, geometry: tuple, max_samples: int) -> SampleSet:
    """``pf_init_model`` with the uniform pose generator over ``free_cells`` (Nav2's global
    localization), weights ``1 / max_samples``; ``geometry`` as
    :attr:`~tfloc.baselines.amcl.map.map.NavMap.geometry`."""
    poses = _uniform_poses(state, free_cells, *geometry, max_samples)
    return clustered(poses, np.full(max_samples, 1.0 / max_samples))


@njit(cache=True, nogil=True, error_model="numpy")
def normalise(weights: np.ndarray, total: float, w_slow: float, w_fast: float, alpha_slow: float,
              alpha_fast: float) -> tuple[float, float]:
    """``pf_update_sensor`` after the model: ``weights`` normalised in place; new ``w_slow``, ``w_fast``."""
    n = weights.shape[0]
    if total > 0.0:
        w_avg = 0.0
        for i in range(n):
            w_avg += weights[i]
            weights[i] /= total
        w_avg /= n
        if w_slow == 0.0:
            w_slow = w_avg
        else:
            w_slow += alpha_slow * (w_avg - w_slow)
        if w_fast == 0.0:
            w_fast = w_avg
        else:
            w_fast += alpha_fast * (w_avg - w_fast)
    else:
        for i in range(n):
            weights[i] = 1.0 / n
    return w_slow, w_fast


@njit(cache=True, nogil=True)
def _pick(c: np.ndarray, n: int, r: float) -> int:
    """The ``i`` with ``c[i] ≤ r < c[i + 1]`` (module notes)."""
    if not c[n] > r:
        return n - 1
    lo = 0
    hi = n
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if c[mid] <= r:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True, nogil=True, error_model="numpy")
def _resample(state: np.ndarray, poses: np.ndarray, weights: np.ndarray, w_slow: float, w_fast: float,
              min_samples: int, max_samples: int, pop_err: float, pop_z: float, free_cells: np.ndarray,
              origin_x: float, origin_y: float, scale: float, size_x: int, size_y: int):  # noqa: ANN202
    n = poses.shape[0]
    c = np.empty(n + 1)
    c[0] = 0.0
    for i in range(n):
        c[i + 1] = c[i] + weights[i]
    tree = kd.alloc(3 * max_samples)
    out = np.empty((max_samples, 3))
    outw = np.empty(max_samples)
    count = 0
    total = 0.0
    w_diff = 1.0 - w_fast / w_slow
    if w_diff < 0.0:
        w_diff = 0.0
    injected = 0
    while count < max_samples:
        idx = count
        count += 1
        if drand48(state) < w_diff:
            uniform_pose(state, free_cells, origin_x, origin_y, scale, size_x, size_y, out[idx])
            injected += 1
        else:
            r = drand48(state)
            i = _pick(c, n, r)
            out[idx, 0] = poses[i, 0]
            out[idx, 1] = poses[i, 1]
            out[idx, 2] = poses[i, 2]
        outw[idx] = 1.0
        total += outw[idx]
        kd.insert(tree, out[idx], outw[idx])
        if count > resample_limit(tree[7][2], min_samples, max_samples, pop_err, pop_z):
            break
    if w_diff > 0.0:
        w_slow = 0.0
        w_fast = 0.0
    out = out[:count].copy()
    outw = outw[:count].copy()
    for i in range(count):
        outw[i] /= total
    stats = _cluster_stats(tree, out, outw)
    return out, outw, tree[7][2], stats, _converged(out), w_slow, w_fast, injected


def resample(state: np.ndarray, s: SampleSet, w_slow: float, w_fast: float, min_samples: int,
             max_samples: int, pop_err: float, pop_z: float, free_cells: np.ndarray,
             geometry: tuple) -> tuple[SampleSet, float, float, int]:
    """``pf_update_resample``: the new set, ``w_slow``, ``w_fast`` and how many random poses were
    injected; ``geometry`` as :attr:`~tfloc.baselines.amcl.map.map.NavMap.geometry`."""
    out, outw, bins, stats, conv, w_slow, w_fast, injected = _resample(
        state, s.poses, s.weights, w_slow, w_fast, min_samples, max_samples, pop_err, pop_z,
        free_cells, *geometry)
    return _sample_set(out, outw, bins, stats, conv), float(w_slow), float(w_fast), int(injected)
