"""The rows of the single-scan tables: ``summary.csv`` (every metric per matcher × grouping),
``paired.csv`` (paired comparisons of success) and the regression guard's reference rows.

:data:`METRICS` names a summary row's metrics in order (counts first as integers, then errors in
cm and degrees, improvements, success with its interval, outcome counts and shares, CPU and wall
time in ms); :class:`SummaryRow` is the grouping's keys followed by them."""

from __future__ import annotations

from dataclasses import dataclass, make_dataclass

#: the outcomes of a scored row, and the label of one not scored (:mod:`tfloc.evaluation.outcome`)
OUTCOME_NAMES = ("success", "local-optimum", "ambiguous", "no-answer")
UNSCORED_NAME = "unscored"

#: a summary row's metrics, in column order
METRICS = (
    "n", "n_truth", "n_est", "n_excluded", "n_timeout", "n_error", "n_invalid",
    "dist_mean_cm", "dist_std_cm", "dist_median_cm", "dist_median_lo_cm", "dist_median_hi_cm",
    "dist_p90_cm", "dist_max_cm",
    "orient_mean_deg", "orient_std_deg", "orient_median_deg", "orient_p90_deg", "orient_max_deg",
    "dist_impr_mean_pct", "dist_impr_median_pct", "dist_impr_min_pct",
    "orient_impr_mean_pct", "orient_impr_median_pct", "orient_impr_min_pct",
    "success_rate_pct", "success_lo_pct", "success_hi_pct",
    *(f"n_{o.replace('-', '_')}" for o in (*OUTCOME_NAMES, UNSCORED_NAME)),
    *(f"share_{o.replace('-', '_')}_pct" for o in OUTCOME_NAMES),
    "n_near", "n_diverged",
    "runtime_median_ms", "runtime_p95_ms", "n_timed",
    "cpu_median_ms", "cpu_median_lo_ms", "cpu_median_hi_ms", "cpu_p95_ms", "n_cpu", "wall_per_cpu_median")

#: a summary row's keys: the grouping (``dataset``, ``overall``, ``scenario-I``, …), the dataset
#: (``all`` pooled), the bin (``all``, an offset bin or a group) and the matcher
SUMMARY_KEYS = ("grouping", "dataset", "bin", "matcher")


def _is_count(name: str) -> bool:
    return name == "n" or name.startswith("n_")


#: one row of ``summary.csv``: :data:`SUMMARY_KEYS`, then :data:`METRICS` (counts as integers)
SummaryRow = make_dataclass(
    "SummaryRow", [(k, str) for k in SUMMARY_KEYS] + [(m, int if _is_count(m) else float) for m in METRICS],
    frozen=True)
SummaryRow.__module__ = __name__


@dataclass(frozen=True)
class PairedRow:
    """One pair of matchers on the scans both answered (``dataset`` or ``all`` pooled): their
    success (%), the scans only one got right, the difference a − b (points) with its bootstrap
    interval, the exact McNemar p and its Holm-adjusted value, and whether it is significant."""

    dataset: str
    a: str
    b: str
    n: int
    success_a_pct: float
    success_b_pct: float
    only_a: int
    only_b: int
    diff_pct: float
    diff_lo_pct: float
    diff_hi_pct: float
    p_mcnemar: float
    p_holm: float
    significant: bool


@dataclass(frozen=True)
class GuardRow:
    """The regression guard's reference for one matcher and group (``results/reference/
    summary.csv``): scans, success (%), mean and median errors (cm, degrees), failure counts."""

    matcher: str
    group: str
    n: int
    success_rate_pct: float
    dist_mean_cm: float
    dist_median_cm: float
    orient_mean_deg: float
    orient_median_deg: float
    n_local_optimum: int
    n_ambiguous: int
    n_no_answer: int


@dataclass(frozen=True)
class GuardTrackingRow:
    """The tracking guard's reference for one matcher and sequence (``results/reference/
    tracking.csv``): scans, tracked share (%), APE RMSE (cm) and unrecovered losses."""

    matcher: str
    group: str
    n: int
    tracked_pct: float
    ape_rmse_cm: float
    unrecovered: int
