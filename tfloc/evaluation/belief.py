"""A tracker's belief at one scan of a sequence, and what its particle weights say (pure: the
snapshot is taken by :mod:`tfloc.harness.belief`, drawn by :mod:`tfloc.report.belief`; ``tfloc
track --draw-at SCAN_ID --figure PATH --explain``).

A tracker may expose its belief through optional read-only accessors (AMCL has them:
:class:`tfloc.baselines.amcl.AmclTracker`); the snapshot takes what is there, right after the
step, outside the timed call:

* ``belief() -> (poses (N, 3), weights (N,))``: the particles as its last update weighed them;
* ``likelihood(poses (M, 3)) -> (M,)``: the factor its sensor model gives the last scan at each
  pose (the weights are these, normalised);
* ``last_motion() -> (before (N, 3), after (N, 3), increment Pose)``: its last motion update.

A tracker without them is drawn with the truth, its prediction and its estimate only. The summary
(:func:`summarize`, metres and degrees) says how sharply the weights pick a pose: the effective
sample size ``1 / Σ w²``, the sensor factor at the truth, at the estimate and half a metre or 10°
off the truth, the share of weight near the truth, the cloud's spread, and the spread the motion
model added at its last update (each particle's pose after minus its pose before ⊕ the odometry
increment, in the particle's frame).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tfloc.core.pose import Pose, angdiff
from tfloc.evaluation.trajectory import LOST_DIST_M, LOST_ORIENT_DEG

#: the probes half a metre or 10° off the truth (robot frame: ahead, behind, left, right; turned)
OFFSET_M, TURN_DEG = 0.5, 10.0
NEAR_M, NEAR_DEG = 0.5, 10.0  # "near the truth" for the share of weight


@dataclass(frozen=True)
class Snapshot:
    """What a tracker held right after its step at one scan (metres, radians).

    Attributes:
        index, scan_id: the scan's position in the sequence and its id.
        estimate, truth, prediction: the step's answer, the truth (``None`` if unknown) and the
            guess it started from (``None`` if not known).
        ranges, angles: the scan (metres) and its beams' bearings (radians).
        info: the step's ``info``.
        particles, weights: ``belief()`` (``None`` without it).
        factors: ``likelihood`` at each particle (``None`` without it).
        probes: ``(name, pose, factor)`` of ``likelihood`` at the truth, the estimate and the
            poses off the truth.
        motion: ``last_motion()`` (``None`` without it).
    """

    index: int
    scan_id: str
    estimate: Pose
    truth: Pose | None
    ranges: np.ndarray
    angles: np.ndarray
    info: dict
    particles: np.ndarray | None = None
    weights: np.ndarray | None = None
    factors: np.ndarray | None = None
    probes: tuple[tuple[str, Pose, float], ...] = ()
    motion: tuple[np.ndarray, np.ndarray, Pose] | None = None
    prediction: Pose | None = None


def is_lost(estimate: Pose, truth: Pose | None) -> bool:
    """Whether ``estimate`` is a loss's (above 0.5 m or 10° from a known ``truth``)."""
    if truth is None:
        return False
    d, o = estimate.error_to(truth)
    return d > LOST_DIST_M or math.degrees(o) > LOST_ORIENT_DEG


def probe_poses(truth: Pose | None, estimate: Pose) -> list[tuple[str, Pose]]:
    """The named poses whose sensor factor the summary reports."""
    out = [("estimate", estimate)]
    if truth is not None:
        out.insert(0, ("truth", truth))
        for name, off in (("0.5 m ahead", Pose(OFFSET_M, 0.0, 0.0)), ("0.5 m behind", Pose(-OFFSET_M, 0.0, 0.0)),
                          ("0.5 m left", Pose(0.0, OFFSET_M, 0.0)), ("0.5 m right", Pose(0.0, -OFFSET_M, 0.0)),
                          ("turned +10°", Pose(0.0, 0.0, math.radians(TURN_DEG))),
                          ("turned −10°", Pose(0.0, 0.0, -math.radians(TURN_DEG)))):
            out.append((name, truth.compose(off)))
    return out


@dataclass(frozen=True)
class BeliefSummary:
    """How sharply a belief's weights pick a pose (module notes; metres, degrees).

    Attributes:
        particles: particles weighed; ``ess``: effective sample size ``1 / Σ w²``.
        max_weight_x_mean: the heaviest particle's weight over the mean weight (``N · max w``).
        factor_mean, factor_max: the sensor factor over the particles (mean, largest).
        factor: ``{probe name: factor}`` (truth, estimate, 0.5 m and 10° off the truth).
        above_truth: share of particles whose factor exceeds the truth's.
        weight_near_truth: weight within 0.5 m and 10° of the truth.
        spread_xy_m, spread_theta_deg: the weighted cloud's sd (√(σx² + σy²); circular heading sd).
        motion_xy_m, motion_theta_deg: RMS of the noise the last motion update added per particle.
        increment_m, increment_deg: the odometry increment of that update.
    """

    particles: int
    ess: float
    max_weight_x_mean: float
    factor_mean: float
    factor_max: float
    factor: dict
    above_truth: float
    weight_near_truth: float
    spread_xy_m: float
    spread_theta_deg: float
    motion_xy_m: float
    motion_theta_deg: float
    increment_m: float
    increment_deg: float


def motion_noise(before: np.ndarray, after: np.ndarray, increment: Pose) -> np.ndarray:
    """Per particle, ``(before ⊕ increment)⁻¹ · after``: the noise a motion update added, in the
    moved particle's frame (``(N, 3)``, metres and radians)."""
    b, a = np.asarray(before, float).reshape(-1, 3), np.asarray(after, float).reshape(-1, 3)
    c, s = np.cos(b[:, 2]), np.sin(b[:, 2])
    ex = b[:, 0] + c * increment.x - s * increment.y
    ey = b[:, 1] + s * increment.x + c * increment.y
    et = b[:, 2] + increment.theta
    dx, dy = a[:, 0] - ex, a[:, 1] - ey
    ce, se = np.cos(et), np.sin(et)
    return np.column_stack([ce * dx + se * dy, -se * dx + ce * dy, angdiff(a[:, 2], et)])


def summarize(snap: Snapshot) -> BeliefSummary | None:
    """:class:`BeliefSummary` of a snapshot with a belief; ``None`` without one."""
    if snap.particles is None or snap.weights is None or len(snap.weights) == 0:
        return None
    p, w = snap.particles, snap.weights / snap.weights.sum()
    nan = math.nan
    factor = {n: v for n, _, v in snap.probes}
    f = snap.factors if snap.factors is not None else np.full(len(w), nan)
    t = snap.truth
    above = near = nan
    if t is not None:
        if "truth" in factor:
            above = float(np.mean(f > factor["truth"]))
        d = np.hypot(p[:, 0] - t.x, p[:, 1] - t.y)
        o = np.degrees(np.abs(angdiff(p[:, 2], t.theta)))
        near = float(w[(d <= NEAR_M) & (o <= NEAR_DEG)].sum())
    mx, my = float(w @ p[:, 0]), float(w @ p[:, 1])
    sxy = math.sqrt(max(float(w @ ((p[:, 0] - mx) ** 2 + (p[:, 1] - my) ** 2)), 0.0))
    r = abs(complex(float(w @ np.cos(p[:, 2])), float(w @ np.sin(p[:, 2]))))
    sth = math.degrees(math.sqrt(max(-2.0 * math.log(max(r, 1e-300)), 0.0)))
    mxy = mth = inc_m = inc_deg = nan
    if snap.motion is not None:
        before, after, inc = snap.motion
        noise = motion_noise(before, after, inc)
        mxy = float(np.sqrt(np.mean(noise[:, 0] ** 2 + noise[:, 1] ** 2)))
        mth = math.degrees(float(np.sqrt(np.mean(noise[:, 2] ** 2))))
        inc_m, inc_deg = math.hypot(inc.x, inc.y), math.degrees(inc.theta)
    return BeliefSummary(len(w), float(1.0 / np.sum(w ** 2)), float(len(w) * w.max()),
                         float(np.nanmean(f)) if np.isfinite(f).any() else nan,
                         float(np.nanmax(f)) if np.isfinite(f).any() else nan,
                         factor, above, near, sxy, sth, mxy, mth, inc_m, inc_deg)
