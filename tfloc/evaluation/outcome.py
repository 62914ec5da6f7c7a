"""Success and the outcome of a localization: the one rule every run, report and note applies.

* **success**: distance error ≤ ``dist_m`` *and* orientation error ≤ ``orient_deg``
  (:class:`Thresholds`; the paper-protocol default is 10 cm and 2°);
* **no-answer**: the matcher gave no pose (it declined, raised or timed out);
* otherwise a failure, told apart by the matcher's own objective (``Matcher.score``):
  **local-optimum** if it scores the true pose lower than its answer (the search stopped short
  of a better optimum), **ambiguous** if not (its objective prefers the wrong pose).

Where a failed search ended (:func:`search_outcome`), measured from the poses alone: the
``local-optimum`` label says nothing about *where* the search stopped (with a noisy objective it
holds almost whenever the objective at the truth sits at its noise floor), so failures are also
told apart as **near** (stopped within 30 cm and 5° of the truth: a stall in the basin) and
**diverged** (ended farther from the true position than the initial guess was).

Inputs are metres and radians; the functions are vectorised (scalars or arrays alike).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tfloc.core.thresholds import Thresholds

SUCCESS, LOCAL_OPTIMUM, AMBIGUOUS, NO_ANSWER = "success", "local-optimum", "ambiguous", "no-answer"
OUTCOMES = (SUCCESS, LOCAL_OPTIMUM, AMBIGUOUS, NO_ANSWER)
NEAR, DIVERGED, OTHER = "near", "diverged", "other"
SEARCH_OUTCOMES = (SUCCESS, NEAR, DIVERGED, OTHER)
NEAR_DIST_M, NEAR_ORIENT_DEG = 0.30, 5.0
NEAR_THRESHOLDS = Thresholds(NEAR_DIST_M, NEAR_ORIENT_DEG)
UNSCORED = "unscored"  # failed under thresholds stricter than the run's, which recorded no scores


def failure_kind(score_est: Any, score_true: Any) -> Any:
    """``local-optimum`` where the matcher's objective is lower at the truth than at its answer,
    else ``ambiguous``."""
    kind = np.where(np.asarray(score_true, dtype=float) < np.asarray(score_est, dtype=float),
                    LOCAL_OPTIMUM, AMBIGUOUS)
    return str(kind) if kind.ndim == 0 else kind


def outcome(answered: Any, dist_err_m: Any, orient_err_rad: Any, score_est: Any, score_true: Any,
            thresholds: Thresholds, recorded: Any = "") -> Any:
    """The outcome of each localization (see the module notes): the one rule, applied by the worker
    when it writes a row and by the metrics when a report re-reads rows (maybe under other
    thresholds). Scores are NaN where they were not taken (a success, or a row whose matcher
    could not score): such a failure keeps its ``recorded`` failure outcome (``local-optimum`` or
    ``ambiguous``), else it is ``unscored``."""
    s_est, s_true = np.asarray(score_est, dtype=float), np.asarray(score_true, dtype=float)
    rec = np.asarray(recorded, dtype=object)
    scored = ~np.isnan(s_est) & ~np.isnan(s_true)
    fail = np.where(scored, failure_kind(s_est, s_true),
                    np.where(np.isin(rec, (LOCAL_OPTIMUM, AMBIGUOUS)), rec, UNSCORED))
    out = np.where(~np.asarray(answered, dtype=bool), NO_ANSWER,
                   np.where(thresholds.success(dist_err_m, orient_err_rad), SUCCESS, fail))
    return str(out) if out.ndim == 0 else out


def search_outcome(dist_err_m: Any, orient_err_rad: Any, init_dist_err_m: Any, thresholds: Thresholds,
                   near: Thresholds = NEAR_THRESHOLDS) -> Any:
    """Where each search ended (:data:`SEARCH_OUTCOMES`, the first rule that holds): ``success``
    (within ``thresholds``), ``near`` (within ``near``), ``diverged`` (farther from the true
    position than the initial guess), else ``other``; NaN errors (no answer) give ``other``."""
    d = np.asarray(dist_err_m, dtype=float)
    out = np.select([thresholds.success(d, orient_err_rad), near.success(d, orient_err_rad),
                     d > np.asarray(init_dist_err_m, dtype=float)], [SUCCESS, NEAR, DIVERGED], OTHER)
    return str(out) if out.ndim == 0 else out.astype(object)
