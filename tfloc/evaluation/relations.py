"""Relation errors as Kümmerle et al. (2009, Sec. 3) report them, for scan-to-scan runs.

For every relation δ* and its estimate δ: the translational error ‖trans(δ ⊖ δ*)‖ (metres) and the
rotational error |rot(δ ⊖ δ*)| (reported in degrees); summarised as mean ± standard deviation and
max, absolute and squared. The standard deviation is the sample one (ddof = 1), as everywhere else
in tfloc's reports (pandas' default), so a note and a report of the same run agree.
"""

from __future__ import annotations

import numpy as np


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
