"""The per-scan judgement the verdict counts: is a tracker's answer *believed tracked*?

Where the others agree on a pose (:mod:`.consensus`), the tracker is believed tracked exactly
when it agrees with them. Where they do not, the scan and the map decide: its answer's fit share
(:mod:`.mapfit`) must be within ``fit_margin`` of the best share any tracker reached on that scan
(an unmapped object hides the same returns from every answer), and its correction must not
disagree with the odometry (:mod:`.odometry`). Each scan's belief says which signal decided it.
"""

from __future__ import annotations

import numpy as np

#: which signal decided a scan's belief
BY_CONSENSUS, BY_FIT = "consensus", "fit"


def best_fit(fits: np.ndarray) -> np.ndarray:
    """``(N,)`` the best fit share any tracker reached at each scan (NaN where none has one)."""
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(fits).any(axis=0)
        return np.where(ok, np.nanmax(np.where(np.isfinite(fits), fits, -np.inf), axis=0), np.nan)


def fits_best(fits: np.ndarray, fit_margin: float) -> np.ndarray:
    """``(M, N)`` whether each answer's fit share is within ``fit_margin`` of its scan's best."""
    best = best_fit(fits)[None, :]
    with np.errstate(invalid="ignore"):
        return np.isfinite(fits) & (fits >= best - fit_margin)


def believed(agree: np.ndarray, known: np.ndarray, fits: np.ndarray, odometry_disagrees: np.ndarray,
             fit_margin: float) -> np.ndarray:
    """``(M, N)`` believed tracked: the consensus where ``known``, else a fit share within
    ``fit_margin`` of the scan's best and no disagreement with the odometry (module notes)."""
    return np.where(known, agree, fits_best(fits, fit_margin) & ~odometry_disagrees)
