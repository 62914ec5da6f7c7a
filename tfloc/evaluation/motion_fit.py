"""What a practitioner measures to tune AMCL for a robot: the odometry's noise as the four α of
the odometry motion model (Nav2's ``alpha1``…``alpha4``, :mod:`tfloc.datasets.motion`) and the
scanner's hit noise (``sigma_hit``), both from a recording with ground truth.

**α**: the sequence is cut where Nav2 would update its filter (the odometry moved
``update_min_d`` along x or y or turned ``update_min_a`` since the last cut) at scans that carry
truth. For each interval the odometry's and the truth's relative motions are decomposed into
``(δrot1, δtrans, δrot2)``; the model says each part's error is zero-mean with variance
``α1·δrot1² + α2·δtrans²`` (rotations) and ``α3·δtrans² + α4·(δrot1² + δrot2²)`` (translation),
so the squared errors are regressed on those terms by non-negative least squares (the rotations
counted forward and backward alike, as Nav2's ``angle_diff``), with 3-sigma clipping: an
interval whose error lies beyond 3 of the model's standard deviations (an encoder that froze,
a wheel that slipped) is left out and the fit repeated, as a practitioner would not tune the
filter's everyday noise to a fault.

**sigma_hit**: at every true pose, the distance from each return's end point to the nearest
occupied cell of the map (the likelihood field's own distance, capped at ``cap_m``); the
likelihood field models it as a zero-mean Gaussian, so its standard deviation is the robust
1.4826 × median absolute value. Units: metres, radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import nnls

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose, wrap_angle
from tfloc.datasets.motion import decompose
from tfloc.maps.fields import distance_field


@dataclass(frozen=True)
class MotionFit:
    """Fitted α (Nav2's ``alpha1``…``alpha4``) from ``intervals`` update intervals."""

    alpha1: float
    alpha2: float
    alpha3: float
    alpha4: float
    intervals: int
    clipped: int
    mean_trans_m: float
    mean_turn_rad: float


def _turn(rot: float) -> float:
    return min(abs(rot), math.pi - abs(rot))


def update_intervals(odom: list[Pose], truth: list[Pose | None], min_d: float = 0.25,
                     min_a: float = 0.2) -> list[tuple[int, int]]:
    """Pairs of scan indices ``(i, j)``, both with truth, where the odometry moved at least
    ``min_d`` along x or y (its own frame) or turned ``min_a`` from ``i`` to ``j``: Nav2's update
    gate, each interval starting where the last one ended."""
    out, start = [], None
    for k, t in enumerate(truth):
        if t is None:
            continue
        if start is None:
            start = k
            continue
        a, b = odom[start], odom[k]
        if (abs(b.x - a.x) >= min_d or abs(b.y - a.y) >= min_d
                or abs(float(wrap_angle(b.theta - a.theta))) >= min_a):
            out.append((start, k))
            start = k
    return out


def fit_motion_noise(odom: list[Pose], truth: list[Pose | None], min_d: float = 0.25,
                     min_a: float = 0.2) -> MotionFit:
    """The α of the odometry motion model that explain ``odom``'s errors against ``truth`` over
    Nav2's update intervals (module notes). Needs at least 4 intervals."""
    rows_r, err_r, rows_t, err_t = [], [], [], []
    trans_all, turn_all = [], []
    for i, j in update_intervals(odom, truth, min_d, min_a):
        o1, ot, o2 = decompose(odom[i].between(odom[j]))
        t1, tt, t2 = decompose(truth[i].between(truth[j]))
        r1, r2 = _turn(t1), _turn(t2)
        rows_r.append((r1 * r1 + r2 * r2, 2.0 * tt * tt))
        err_r.append(float(wrap_angle((o1 + o2) - (t1 + t2))) ** 2)
        rows_t.append((tt * tt, r1 * r1 + r2 * r2))
        err_t.append((ot - tt) ** 2)
        trans_all.append(tt)
        turn_all.append(r1 + r2)
    if len(rows_t) < 4:
        raise ValueError(f"{len(rows_t)} update intervals with truth at both ends: too few to fit α")
    (a1, a2), keep_r = _clipped_nnls(np.asarray(rows_r), np.asarray(err_r))
    (a3, a4), keep_t = _clipped_nnls(np.asarray(rows_t), np.asarray(err_t))
    clipped = int((~keep_t | ~keep_r).sum())
    return MotionFit(float(a1), float(a2), float(a3), float(a4), len(rows_t), clipped,
                     float(np.mean(trans_all)), float(np.mean(turn_all)))


def _clipped_nnls(a: np.ndarray, sq_err: np.ndarray, k: float = 3.0,
                  rounds: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """Non-negative least squares of squared errors on the variance terms ``a``, refitted
    without the rows whose error exceeds ``k`` model standard deviations; returns the
    coefficients and which rows were kept."""
    keep = np.ones(len(sq_err), dtype=bool)
    x = np.zeros(a.shape[1])
    for _ in range(rounds):
        x, _ = nnls(a[keep], sq_err[keep])
        var = a @ x
        new = sq_err <= k * k * np.maximum(var, 1e-12)
        if np.array_equal(new, keep):
            break
        keep = new
    return x, keep


def fit_sigma_hit(map_, laser: LaserSpec, scans: list[np.ndarray], poses: list[Pose],
                  resolution: float = 0.05, cap_m: float = 2.0) -> tuple[float, int]:
    """The likelihood field's ``sigma_hit`` (metres) from scans at their true poses, and the
    number of end points it was measured on (module notes)."""
    field = distance_field(map_, resolution, cap_m)
    dist = []
    for ranges, pose in zip(scans, poses, strict=True):
        pts = pose.transform(laser.to_points(ranges))
        dist.append(field.interpolate(pts))
    d = np.concatenate(dist) if dist else np.zeros(0)
    d = d[np.isfinite(d) & (d < cap_m)]
    return float(1.4826 * np.median(np.abs(d))) if d.size else math.nan, int(d.size)
