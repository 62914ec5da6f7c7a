"""A tracker's belief at one scan of a sequence: what its particle weights say, and a picture of it
(``tfloc track --draw-at SCAN_ID --figure PATH --explain``).

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
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from tfloc.core.pose import Pose, angdiff, wrap_angle
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


def take_snapshot(tracker, index: int, scan_id: str, ranges: np.ndarray, angles: np.ndarray,
                  estimate: Pose, truth: Pose | None, info: dict) -> Snapshot:
    """The tracker's belief right after its step at scan ``index`` (module notes)."""
    belief = getattr(tracker, "belief", None)
    got = belief() if callable(belief) else None
    particles, weights = (None, None) if got is None else (np.asarray(got[0], float), np.asarray(got[1], float))
    factors, probes = None, ()
    like = getattr(tracker, "likelihood", None)
    if callable(like) and particles is not None:
        factors = np.asarray(like(particles), float)
        named = probe_poses(truth, estimate)
        values = np.asarray(like(np.array([p.as_array() for _, p in named])), float)
        probes = tuple((n, p, float(v)) for (n, p), v in zip(named, values, strict=True))
    last = getattr(tracker, "last_motion", None)
    motion = last() if callable(last) else None
    return Snapshot(index, str(scan_id), estimate, truth, np.asarray(ranges, float), np.asarray(angles, float),
                    dict(info), particles, weights, factors, probes, motion)


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


def explain(snap: Snapshot) -> str:
    """The snapshot as a few lines of text: errors, the step's info, the belief's summary."""
    lines = [f"scan {snap.scan_id} (#{snap.index}):"]
    for name, pose in (("estimate", snap.estimate), ("prediction", snap.prediction)):
        if pose is None:
            continue
        err = ""
        if snap.truth is not None:
            d, o = pose.error_to(snap.truth)
            err = f"  error {100 * d:.1f} cm, {math.degrees(o):.1f}°"
        lines.append(f"  {name:<10} x {pose.x:.3f} y {pose.y:.3f} θ {math.degrees(wrap_angle(pose.theta)):.1f}°{err}")
    if snap.truth is not None:
        t = snap.truth
        lines.append(f"  {'truth':<10} x {t.x:.3f} y {t.y:.3f} θ {math.degrees(wrap_angle(t.theta)):.1f}°")
    keys = ("updated", "resampled", "particles", "clusters", "cluster_weight", "sigma_xy_m", "sigma_theta_rad")
    shown = {k: snap.info[k] for k in keys if k in snap.info}
    if shown:
        lines.append("  info: " + ", ".join(f"{k} {_fmt(v)}" for k, v in shown.items()))
    s = summarize(snap)
    if s is None:
        lines.append("  belief: the tracker exposes none")
        return "\n".join(lines)
    lines += [f"  belief (the last update's weighed particles): {s.particles} particles, effective sample "
              f"size {s.ess:.0f} ({100 * s.ess / s.particles:.0f} %), heaviest weight {s.max_weight_x_mean:.2f}"
              " × the mean",
              f"  cloud sd: {100 * s.spread_xy_m:.1f} cm (xy), {s.spread_theta_deg:.1f}° (heading); weight within "
              f"{NEAR_M:g} m and {NEAR_DEG:g}° of the truth: {_pct(s.weight_near_truth)}",
              f"  sensor factor p = 1 + Σ pz³: particles mean {s.factor_mean:.3f}, max {s.factor_max:.3f}; "
              f"particles above the truth's: {_pct(s.above_truth)}"]
    if s.factor:
        lines.append("  p at " + ", ".join(f"{n} {v:.3f}" for n, v in s.factor.items()))
    if math.isfinite(s.motion_xy_m):
        lines.append(f"  last motion update: odometry {100 * s.increment_m:.1f} cm, {s.increment_deg:.1f}°; "
                     f"noise added per particle (RMS) {100 * s.motion_xy_m:.1f} cm, {s.motion_theta_deg:.1f}°")
    return "\n".join(lines)


def _fmt(v) -> str:
    return f"{v:.3f}" if isinstance(v, float) else str(v)


def _pct(v: float) -> str:
    return "–" if not math.isfinite(v) else f"{100 * v:.1f} %"


def _arrow(ax, pose: Pose, colour: str, label: str, length: float = 0.9) -> None:
    ax.annotate("", xy=(pose.x + length * math.cos(pose.theta), pose.y + length * math.sin(pose.theta)),
                xytext=(pose.x, pose.y), zorder=6,
                arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 2.2, "mutation_scale": 14})
    ax.plot(pose.x, pose.y, "o", color=colour, ms=7, mec="white", mew=0.8, label=label, zorder=7)


def _endpoints(snap: Snapshot, pose: Pose, max_range: float) -> np.ndarray:
    ok = np.isfinite(snap.ranges) & (snap.ranges < max_range)
    a = pose.theta + snap.angles[ok]
    return np.column_stack([pose.x + snap.ranges[ok] * np.cos(a), pose.y + snap.ranges[ok] * np.sin(a)])


def fig_belief(snap: Snapshot, the_map, path: Path, title: str, max_range: float,
               radius_m: float = 3.0) -> Path:
    """Left: the map within ``radius_m`` of the robot, the truth, the prediction and the estimate
    (arrows), the scan's end points from the truth and from the estimate, the particles coloured
    by weight. Right (with a belief and a truth): each particle's distance and heading from the
    truth, coloured by weight."""
    from matplotlib import colors

    centre = snap.truth or snap.estimate
    have = snap.particles is not None and snap.weights is not None
    two = have and snap.truth is not None
    fig = Figure(figsize=(12.5 if two else 7.0, 6.0), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, 2 if two else 1, width_ratios=[1.25, 1] if two else None))
    ax = axes[0]
    from .figures import MAP_SPACING_M

    mp, _ = the_map.sample_points(MAP_SPACING_M)
    near = (np.abs(mp[:, 0] - centre.x) <= radius_m) & (np.abs(mp[:, 1] - centre.y) <= radius_m)
    ax.scatter(mp[near, 0], mp[near, 1], s=3, c="black", marker="s", linewidths=0, label="map")
    norm = None
    if have:
        w = snap.weights / snap.weights.sum()
        pos = w[w > 0]
        norm = colors.LogNorm(vmin=max(float(pos.min()), float(pos.max()) * 1e-4), vmax=float(pos.max())) \
            if pos.size and pos.max() > pos.min() else None
        order = np.argsort(w)
        sc = ax.scatter(snap.particles[order, 0], snap.particles[order, 1], c=np.maximum(w[order], 1e-300),
                        s=6, cmap="viridis", norm=norm, linewidths=0, label="particles", zorder=3)
        fig.colorbar(sc, ax=axes.tolist(), shrink=0.8, label="particle weight (normalised)")
    if snap.truth is not None:
        e = _endpoints(snap, snap.truth, max_range)
        ax.scatter(e[:, 0], e[:, 1], s=4, c="#2ca02c", linewidths=0, alpha=0.6, label="scan from the truth", zorder=2)
    e = _endpoints(snap, snap.estimate, max_range)
    ax.scatter(e[:, 0], e[:, 1], s=4, c="#d62728", linewidths=0, alpha=0.6, label="scan from the estimate", zorder=2)
    if snap.truth is not None:
        _arrow(ax, snap.truth, "#2ca02c", "truth")
    if snap.prediction is not None:
        _arrow(ax, snap.prediction, "#ff7f0e", "prediction")
    _arrow(ax, snap.estimate, "#d62728", "estimate")
    ax.set_xlim(centre.x - radius_m, centre.x + radius_m)
    ax.set_ylim(centre.y - radius_m, centre.y + radius_m)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(fontsize=7, loc="upper left", markerscale=1.5)
    if two:
        ax2 = axes[1]
        w = snap.weights / snap.weights.sum()
        t = snap.truth
        d = np.hypot(snap.particles[:, 0] - t.x, snap.particles[:, 1] - t.y)
        o = np.degrees(angdiff(snap.particles[:, 2], t.theta))
        order = np.argsort(w)
        ax2.scatter(d[order], o[order], c=np.maximum(w[order], 1e-300), s=6, cmap="viridis", norm=norm, linewidths=0)
        de, oe = snap.estimate.error_to(t)
        ax2.plot(de, math.degrees(float(angdiff(snap.estimate.theta, t.theta))), "X", color="#d62728", ms=10,
                 label=f"estimate ({100 * de:.0f} cm, {math.degrees(oe):.1f}°)")
        ax2.axhspan(-LOST_ORIENT_DEG, LOST_ORIENT_DEG, color="grey", alpha=0.12, label="within 10°")
        ax2.axvline(LOST_DIST_M, color="grey", ls="--", lw=0.8, label="0.5 m")
        ax2.set_xlabel("particle's distance from the truth (m)")
        ax2.set_ylabel("particle's heading − true heading (°)")
        ax2.legend(fontsize=7, loc="upper right")
        ax2.set_title("particles relative to the truth", fontsize=10)
    s = summarize(snap)
    sub = "" if s is None else (f"\n{s.particles} particles, effective sample size {s.ess:.0f}, "
                                f"cloud sd {100 * s.spread_xy_m:.0f} cm / {s.spread_theta_deg:.0f}°, "
                                f"clusters {snap.info.get('clusters', '–')}")
    ax.set_title(f"{title}: scan {snap.scan_id}{sub}", fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path


#: ``--draw-at first-loss``: the first scan whose estimate is lost (truth known, > 0.5 m or 10°)
FIRST_LOSS = "first-loss"


class Watch:
    """The tracking loop's ``progress`` callback that takes one :class:`Snapshot`: after the step
    at scan index ``target``, or with ``target`` :data:`FIRST_LOSS` at the first scan whose
    estimate is lost. The estimate is read as ``tracker.predict(Pose())`` (the belief carried by
    no motion); :meth:`result` completes the snapshot from the loop's row."""

    def __init__(self, tracker, scans, angles: np.ndarray, target: int | str) -> None:
        self.tracker, self.scans, self.angles, self.target = tracker, scans, angles, target
        self.snapshot: Snapshot | None = None

    def __call__(self, k: int) -> None:
        if self.snapshot is not None:
            return
        scan = self.scans[k]
        if self.target != k and self.target != FIRST_LOSS:
            return
        est = self.tracker.predict(Pose())
        if self.target == FIRST_LOSS and not is_lost(est, scan.true):
            return
        self.snapshot = take_snapshot(self.tracker, k, scan.scan_id, scan.ranges, self.angles, est, scan.true, {})

    def result(self, rows: list) -> Snapshot | None:
        """The snapshot with the row's estimate, prediction and ``info`` (rows:
        :class:`~tfloc.core.result.ResultRow`); ``None`` if none was taken."""
        import dataclasses

        if self.snapshot is None:
            return None
        r = rows[self.snapshot.index]
        return dataclasses.replace(self.snapshot, estimate=Pose(r.est_x, r.est_y, r.est_theta),
                                   prediction=Pose(r.init_x, r.init_y, r.init_theta), info=dict(r.info or {}))
