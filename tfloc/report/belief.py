"""A tracker's belief at one scan drawn, and told in a few lines (``tfloc track --draw-at SCAN_ID
--figure PATH --explain``): the snapshot and its summary are :mod:`tfloc.evaluation.belief`'s."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from tfloc.core.pose import Pose, angdiff, wrap_angle
from tfloc.evaluation.belief import NEAR_DEG, NEAR_M, Snapshot, summarize
from tfloc.evaluation.trajectory import LOST_DIST_M, LOST_ORIENT_DEG


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
