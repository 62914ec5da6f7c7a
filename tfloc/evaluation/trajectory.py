"""Scoring a tracked sequence: evo's APE and RPE, and what a robot operator sees.

Inputs are one sequence's estimates and truths, ``(N, 3)`` arrays of SE(2) poses (metres,
radians) in scan order, in the map frame; rows without truth are left out of every figure. The
trajectories go to evo (``PoseTrajectory3D`` at z = 0, yaw about z) with **no alignment**: a
localizer must be right in the map's frame.

* **APE** (evo ``metrics.APE``): translation error per scan (RMSE, mean, max; metres) and
  rotation angle error (RMSE, max; degrees).
* **RPE per metre** (evo ``metrics.RPE``, ``delta = 1``, ``delta_unit = meters``): the error of
  the relative motion over pose pairs about 1 m of true travel apart; translation RMSE (metres per
  metre) and rotation-angle RMSE (degrees per metre). NaN when the truth travels less than 1 m.
* **tracked**: the share of scans whose error is within the success thresholds
  (:class:`~tfloc.evaluation.outcome.Thresholds`, default 10 cm and 2°).
* **lost**: a scan whose distance error exceeds :data:`LOST_DIST_M` (0.5 m) or orientation error
  exceeds :data:`LOST_ORIENT_DEG` (10°). A **loss** is the start of a lost stretch: a lost scan
  whose previous scan (or the start) was not lost after the last recovery. A **recovery** ends a
  loss: the first later scan back within the success thresholds (the tracker's own doing: the
  loop never resets it). A loss with no recovery by the last scan is **unrecovered**.
* **longest lost stretch** (metres): the true distance travelled from a loss's first scan to its
  recovery scan (or to the last scan), the largest over the losses; 0 without a loss.
* **jumps**: how far each estimate lies from the prediction it started from (``init_*``: the
  last estimate carried by the odometry), every row, truth or not: the largest (metres) and how
  many exceed :data:`JUMP_M` (1 m). A tracker that leaves a correct track for a wrong place, or
  comes back, jumps.
* **CPU ms per scan**: the median of the rows' ``cpu_s`` (every row, truth or not), milliseconds.
"""

from __future__ import annotations

import math

import numpy as np

from tfloc.core.pose import angdiff
from tfloc.core.rows.tracking import TrackScore
from tfloc.core.thresholds import Thresholds

LOST_DIST_M, LOST_ORIENT_DEG = 0.5, 10.0
JUMP_M = 1.0
DEFAULT = Thresholds()


def _traj(poses: np.ndarray, stamps: np.ndarray):
    """An evo ``PoseTrajectory3D`` of SE(2) poses (z = 0, yaw about z)."""
    from evo.core.trajectory import PoseTrajectory3D

    p = np.asarray(poses, dtype=float)
    half = p[:, 2] / 2.0
    quat = np.column_stack([np.cos(half), np.zeros(len(p)), np.zeros(len(p)), np.sin(half)])
    xyz = np.column_stack([p[:, 0], p[:, 1], np.zeros(len(p))])
    return PoseTrajectory3D(positions_xyz=xyz, orientations_quat_wxyz=quat, timestamps=stamps)


def ape(est: np.ndarray, true: np.ndarray) -> dict[str, float]:
    """evo's APE, no alignment: translation RMSE/mean/max (m), rotation angle RMSE/max (°)."""
    from evo.core import metrics

    t = np.arange(len(est), dtype=float)
    data = (_traj(true, t), _traj(est, t))
    out = {}
    m = metrics.APE(metrics.PoseRelation.translation_part)
    m.process_data(data)
    out.update(rmse_m=m.get_statistic(metrics.StatisticsType.rmse),
               mean_m=m.get_statistic(metrics.StatisticsType.mean),
               max_m=m.get_statistic(metrics.StatisticsType.max))
    r = metrics.APE(metrics.PoseRelation.rotation_angle_deg)
    r.process_data(data)
    out.update(rot_rmse_deg=r.get_statistic(metrics.StatisticsType.rmse),
               rot_max_deg=r.get_statistic(metrics.StatisticsType.max))
    return {k: float(v) for k, v in out.items()}


def rpe_per_metre(est: np.ndarray, true: np.ndarray) -> dict[str, float]:
    """evo's RPE over pairs ~1 m of true travel apart: translation RMSE (m/m), rotation (°/m)."""
    from evo.core import metrics
    from evo.core.units import Unit

    if len(true) < 2 or path_length(true)[-1] < 1.0:
        return {"trans_m_per_m": math.nan, "rot_deg_per_m": math.nan}
    t = np.arange(len(est), dtype=float)
    data = (_traj(true, t), _traj(est, t))
    out = {}
    for key, rel in (("trans_m_per_m", metrics.PoseRelation.translation_part),
                     ("rot_deg_per_m", metrics.PoseRelation.rotation_angle_deg)):
        m = metrics.RPE(rel, delta=1.0, delta_unit=Unit.meters, all_pairs=False)
        try:
            m.process_data(data)
        except metrics.MetricsException:
            out[key] = math.nan
            continue
        out[key] = float(m.get_statistic(metrics.StatisticsType.rmse))
    return out


def path_length(true: np.ndarray) -> np.ndarray:
    """Cumulative true distance travelled at each scan (metres; 0 at the first)."""
    p = np.asarray(true, dtype=float)
    steps = np.hypot(np.diff(p[:, 0]), np.diff(p[:, 1]))
    return np.concatenate([[0.0], np.cumsum(steps)])


def errors(est: np.ndarray, true: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-scan distance error (m) and absolute orientation error (rad)."""
    e, t = np.asarray(est, dtype=float), np.asarray(true, dtype=float)
    return np.hypot(e[:, 0] - t[:, 0], e[:, 1] - t[:, 1]), np.abs(angdiff(e[:, 2], t[:, 2]))


def episodes(dist_err: np.ndarray, orient_err: np.ndarray,
             thresholds: Thresholds = DEFAULT) -> list[tuple[int, int | None]]:
    """Lost stretches as ``(first lost scan, recovery scan or None)`` (module notes)."""
    lost = (dist_err > LOST_DIST_M) | (np.degrees(orient_err) > LOST_ORIENT_DEG)
    ok = thresholds.success(dist_err, orient_err)
    out: list[tuple[int, int | None]] = []
    k, n = 0, len(lost)
    while k < n:
        if not lost[k]:
            k += 1
            continue
        back = np.flatnonzero(ok[k + 1:])
        if back.size == 0:
            out.append((k, None))
            break
        rec = k + 1 + int(back[0])
        out.append((k, rec))
        k = rec
    return out


def score_track(est: np.ndarray, true: np.ndarray, cpu_s: np.ndarray | None = None,
                thresholds: Thresholds = DEFAULT, pred: np.ndarray | None = None) -> TrackScore:
    """Every score of one sequence (module notes). ``true`` rows with NaN are left out;
    ``pred``: the predictions the estimates started from (for the jumps)."""
    est, true = np.asarray(est, dtype=float).reshape(-1, 3), np.asarray(true, dtype=float).reshape(-1, 3)
    n_scans = len(est)
    jump = np.full(0, np.nan)
    if pred is not None:
        p = np.asarray(pred, dtype=float).reshape(-1, 3)
        jump = np.hypot(est[:, 0] - p[:, 0], est[:, 1] - p[:, 1])
        jump = jump[np.isfinite(jump)]
    jumps = {"max_jump_m": float(jump.max()) if jump.size else math.nan, "jumps": int((jump > JUMP_M).sum())}
    has = np.isfinite(true).all(axis=1) & np.isfinite(est).all(axis=1)
    e, t = est[has], true[has]
    cpu = math.nan if cpu_s is None or len(cpu_s) == 0 else float(np.median(np.asarray(cpu_s, float))) * 1e3
    if len(t) == 0:
        nan = math.nan
        return TrackScore(n_scans, 0, nan, nan, 0, 0, 0, 0, nan, nan, nan, nan, nan, nan, nan, nan, cpu, **jumps)
    d, o = errors(e, t)
    ok = thresholds.success(d, o)
    eps = episodes(d, o, thresholds)
    s = path_length(t)
    stretches = [s[r if r is not None else len(s) - 1] - s[k] for k, r in eps]
    a = ape(e, t)
    r = rpe_per_metre(e, t)
    return TrackScore(
        n_scans=n_scans, n_truth=int(has.sum()), distance_m=float(s[-1]),
        tracked=float(ok.mean()), n_tracked=int(ok.sum()),
        losses=len(eps), recoveries=sum(rec is not None for _, rec in eps),
        unrecovered=sum(rec is None for _, rec in eps),
        longest_lost_m=float(max(stretches, default=0.0)),
        ape_rmse_m=a["rmse_m"], ape_mean_m=a["mean_m"], ape_max_m=a["max_m"],
        ape_rot_rmse_deg=a["rot_rmse_deg"], ape_rot_max_deg=a["rot_max_deg"],
        rpe_trans_m_per_m=r["trans_m_per_m"], rpe_rot_deg_per_m=r["rot_deg_per_m"],
        cpu_ms_median=cpu, **jumps)


def score_rows(rows, thresholds: Thresholds = DEFAULT) -> TrackScore:
    """:func:`score_track` of one (sequence, matcher)'s result rows (dicts or a DataFrame, in
    scan order, columns ``est_*``, ``true_*``, ``cpu_s`` as numbers; no truth = None or NaN)."""
    import pandas as pd

    from tfloc.core.result import ResultRow

    if isinstance(rows, list) and rows and isinstance(rows[0], ResultRow):
        cols = ("est_x", "est_y", "est_theta", "true_x", "true_y", "true_theta", "init_x", "init_y", "init_theta",
                "cpu_s")
        rows = [{c: getattr(r, c) for c in cols} for r in rows]
    df = pd.DataFrame(rows)
    num = lambda cols: df[cols].to_numpy(float)  # noqa: E731
    cpu = df["cpu_s"].dropna().to_numpy(float)
    pred = num(["init_x", "init_y", "init_theta"]) if "init_x" in df else None
    return score_track(num(["est_x", "est_y", "est_theta"]), num(["true_x", "true_y", "true_theta"]),
                       cpu, thresholds, pred)


def pooled_share(k, n, n_boot: int = 2000, seed: int = 20261122) -> tuple[float, float, float]:
    """The share Σk/Σn pooled over sequences (``k`` tracked of ``n`` scans each) and its 95 %
    percentile-bootstrap interval over sequences (resampled with replacement, seeded); the
    interval is NaN with fewer than two sequences (scans of one sequence are not independent)."""
    k, n = np.asarray(k, dtype=float), np.asarray(n, dtype=float)
    share = float(k.sum() / n.sum()) if n.sum() > 0 else math.nan
    if len(k) < 2 or not n.sum() > 0:
        return share, math.nan, math.nan
    idx = np.random.default_rng(seed).integers(0, len(k), size=(n_boot, len(k)))
    with np.errstate(invalid="ignore", divide="ignore"):   # a draw of unscored sequences only
        boot = k[idx].sum(axis=1) / n[idx].sum(axis=1)
    lo, hi = np.nanpercentile(boot, [2.5, 97.5])
    return share, float(lo), float(hi)
