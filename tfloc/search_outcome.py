"""Where a failed local search ended, relative to the truth and to where it started.

The harness's ``local-optimum`` label (the matcher's objective is lower at the truth than at its
answer) says nothing about *where* the search stopped: with a noisy objective it holds almost
whenever the objective at the truth sits at its noise floor. These labels are measured from
the poses alone (metres, radians):

* ``success``: within the success thresholds (default 10 cm and 2°);
* ``near``: not a success, but stopped near the truth (≤ 30 cm and ≤ 5°), a stall in the basin;
* ``diverged``: ended farther from the true position than the initial guess was;
* ``other``: none of these (closer than it started, but not near the truth).
"""

from __future__ import annotations

import math

import numpy as np

SEARCH_OUTCOMES = ("success", "near", "diverged", "other")


def search_outcome(dist_err_m: np.ndarray, orient_err_rad: np.ndarray, init_dist_err_m: np.ndarray,
                   success_dist_m: float = 0.10, success_orient_rad: float = math.radians(2.0),
                   near_dist_m: float = 0.30, near_orient_rad: float = math.radians(5.0)) -> np.ndarray:
    """The label of :data:`SEARCH_OUTCOMES` for each answer (first matching rule wins, in that
    order); errors are absolute (metres, radians). NaN errors (no answer) give ``other``."""
    d = np.asarray(dist_err_m, dtype=float)
    o = np.abs(np.asarray(orient_err_rad, dtype=float))
    d0 = np.asarray(init_dist_err_m, dtype=float)
    return np.select([(d <= success_dist_m) & (o <= success_orient_rad),
                      (d <= near_dist_m) & (o <= near_orient_rad),
                      d > d0],
                     ["success", "near", "diverged"], "other").astype(object)
