"""Relation errors as Kümmerle et al. (2009, Sec. 3) report them, for scan-to-scan runs.

For every relation δ* and its estimate δ: the translational error ‖trans(δ ⊖ δ*)‖ (metres) and the
rotational error |rot(δ ⊖ δ*)| (reported in degrees); summarised as mean ± standard deviation and
max, absolute and squared. The standard deviation is the sample one (ddof = 1), as everywhere else
in tfloc's reports (pandas' default), so a note and a report of the same run agree.

A tracked trajectory is scored the same way (:func:`tracked_relation_errors`): the estimate of a
relation is the relative pose between the trajectory's estimates at the relation's two stamps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tfloc.core.pose import wrap_angle
from tfloc.core.relation import Relation


def sample_std(values: np.ndarray) -> float:
    """Sample standard deviation (ddof = 1); NaN for fewer than two values."""
    v = np.asarray(values, float)
    return float(v.std(ddof=1)) if v.size > 1 else float("nan")


def relation_stats(trans_m: np.ndarray, rot_rad: np.ndarray, success: np.ndarray | None = None,
                   runtime_s: np.ndarray | None = None) -> dict:
    """Kümmerle-style summary of per-relation errors (m, rad in; m, deg, ms out)."""
    t = np.asarray(trans_m, float)
    r = np.degrees(np.abs(np.asarray(rot_rad, float)))
    out = {"n": int(t.size), "trans_mean_m": t.mean(), "trans_std_m": sample_std(t), "trans_max_m": t.max(),
           "trans_sq_mean_m2": (t ** 2).mean(), "trans_sq_std_m2": sample_std(t ** 2),
           "rot_mean_deg": r.mean(), "rot_std_deg": sample_std(r), "rot_max_deg": r.max(),
           "rot_sq_mean_deg2": (r ** 2).mean(), "rot_sq_std_deg2": sample_std(r ** 2)}
    if success is not None:
        out["success"] = float(np.mean(success))
    if runtime_s is not None and np.size(runtime_s):
        out["runtime_median_ms"] = 1e3 * float(np.median(runtime_s))
        out["runtime_mean_ms"] = 1e3 * float(np.mean(runtime_s))
    return out


@dataclass(frozen=True, eq=False)
class TrackedRelationErrors:
    """Relation errors of a tracked trajectory: ``trans_m``/``rot_rad`` per scored relation,
    ``used`` their indices into the relations, ``skipped`` how many relations had a stamp in no
    row (or a non-finite estimate there)."""

    trans_m: np.ndarray
    rot_rad: np.ndarray
    used: np.ndarray
    skipped: int


def _nearest(sorted_s: np.ndarray, t: np.ndarray, tolerance_s: float) -> np.ndarray:
    """Index into ``sorted_s`` of the stamp nearest each ``t``, −1 where none is within tolerance."""
    i = np.clip(np.searchsorted(sorted_s, t), 1, max(len(sorted_s) - 1, 1))
    lo = np.clip(i - 1, 0, len(sorted_s) - 1)
    hi = np.clip(i, 0, len(sorted_s) - 1)
    best = np.where(np.abs(sorted_s[hi] - t) < np.abs(sorted_s[lo] - t), hi, lo)
    return np.where(np.abs(sorted_s[best] - t) <= tolerance_s, best, -1)


def tracked_relation_errors(stamps_s: np.ndarray, poses: np.ndarray, relations: Sequence[Relation],
                            tolerance_s: float = 5e-5) -> TrackedRelationErrors:
    """Score a tracked trajectory against relations (Kümmerle et al. 2009): for each relation
    whose ``t1`` and ``t2`` are stamps of rows (within ``tolerance_s`` seconds; relations files
    print 5 decimals), the estimated relative pose δ = est(t1)⁻¹ · est(t2) against the relation δ*:
    the translational error ‖trans(δ ⊖ δ*)‖ (m) and the rotational error rot(δ ⊖ δ*) (rad).

    ``stamps_s`` ``(N,)`` seconds and ``poses`` ``(N, 3)`` (m, rad, map frame) are the rows of a
    tracking run in any order; a relation whose stamps are not in the rows is counted and skipped."""
    t = np.asarray(stamps_s, dtype=float).reshape(-1)
    p = np.asarray(poses, dtype=float).reshape(-1, 3)
    order = np.argsort(t, kind="stable")
    st, sp = t[order], p[order]
    n = len(relations)
    if not len(st) or not n:
        return TrackedRelationErrors(np.empty(0), np.empty(0), np.empty(0, dtype=np.int64), n)
    i1 = _nearest(st, np.array([r.t1 for r in relations], dtype=float), tolerance_s)
    i2 = _nearest(st, np.array([r.t2 for r in relations], dtype=float), tolerance_s)
    ok = (i1 >= 0) & (i2 >= 0)
    ok[ok] = np.isfinite(sp[i1[ok]]).all(axis=1) & np.isfinite(sp[i2[ok]]).all(axis=1)
    used = np.flatnonzero(ok)
    a, b = sp[i1[used]], sp[i2[used]]
    c, s = np.cos(a[:, 2]), np.sin(a[:, 2])
    dx, dy = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    est = np.column_stack([c * dx + s * dy, -s * dx + c * dy, b[:, 2] - a[:, 2]])
    ref = np.array([relations[k].delta.as_array() for k in used]).reshape(-1, 3)
    trans = np.hypot(est[:, 0] - ref[:, 0], est[:, 1] - ref[:, 1])
    rot = wrap_angle(est[:, 2] - ref[:, 2])
    return TrackedRelationErrors(trans, rot, used, n - len(used))


def tracked_relation_stats(stamps_s: np.ndarray, poses: np.ndarray, relations: Sequence[Relation],
                           tolerance_s: float = 5e-5) -> dict:
    """:func:`relation_stats` of :func:`tracked_relation_errors` (m, deg; mean ± sample std), with
    ``n_relations`` and ``n_skipped``; NaN figures when no relation could be scored."""
    e = tracked_relation_errors(stamps_s, poses, relations, tolerance_s)
    if e.trans_m.size:
        out = relation_stats(e.trans_m, e.rot_rad)
    else:
        out = {"n": 0, **{k: float("nan") for k in relation_stats(np.zeros(1), np.zeros(1)) if k != "n"}}
    return {**out, "n_relations": len(relations), "n_skipped": e.skipped}


