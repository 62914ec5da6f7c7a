"""The report's Definitions section: how every number of a benchmark report is defined (errors,
improvement, success, outcomes, which rows count, CPU time, intervals, paired tests, bins, the
paper's scenarios as the run's datasets declare them)."""

from __future__ import annotations

from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.paired import ALPHA
from tfloc.evaluation.paper import CITATION
from tfloc.evaluation.summary import declaring


def _scenario_definition(paper: dict) -> str:
    """Which datasets of the run pose the paper's scenarios (as their ``scenario.json`` declare)."""
    one, two, three = (", ".join(declaring(paper, k)) or "none in this run" for k in ("I", "II", "III"))
    return (f"I = datasets {one}; II = {two} by initial angle offset; III = {three} by initial "
            "distance offset (as each dataset's `scenario.json` declares, `paper_scenarios`)")


def definitions(thr: Thresholds, paper: dict | None = None) -> str:
    """How every number of the report is defined."""
    return f"""## Definitions

- **Distance error** ‖(x̂, ŷ) − (x, y)‖ in cm; **orientation error** |angdiff(θ̂, θ)| in degrees
  (the paper's Eq. 6). Mean, median, p90 (linear interpolation between order statistics), max.
- **Improvement** (the paper's Tables 2–4): per scan, distance improvement = 100·(1 − dist_err /
  init_dist_err) and orientation improvement = 100·(1 − orient_err / init_orient_err), where
  init_* is the error of the initial pose; the tables give the **mean of the per-scan values**.
  It is 100 % for a perfect answer, 0 % for no change and negative when the answer is worse than
  the initial pose — one diverged scan with a small initial offset can pull the mean far below 0
  (the worst per-scan value is in summary.csv, `*_impr_min_pct`). Scans with a zero initial
  offset have no improvement and are left out of it.
- **Success**: status `ok` and distance error ≤ {thr.dist_m * 100:g} cm and orientation error ≤
  {thr.orient_deg:g}°. The **success rate** is over all scans with ground truth: a scan without
  an answer counts as a failure.
- **Outcome** of each scan: `success`; `local-optimum` (the matcher's own objective is lower at
  the true pose than at its answer: the search stopped short); `ambiguous` (its objective prefers
  the wrong pose); `no-answer` (status `failed`: the matcher declined or returned no finite pose;
  `timeout`; `error`; `invalid`: the data poses no problem, e.g. the initial pose lies outside the
  map, and no matcher ran; counted apart from errors).
- **Which rows count**: error and improvement statistics use scans with an estimate (status `ok`,
  or `failed` with a finite pose). Timeouts, errors and failed scans without a pose have no error;
  they are **excluded** from those statistics (the `n` column says how many: "(k excl.)") but
  count as failures in the success rate and as `no-answer` in the outcomes.
- **Runtime** per scan is **CPU time**: the worker process's CPU time (all its threads; every
  library runs one thread) during the matcher's `localize` call only (data loading, numba
  compilation and what depends only on the map are done before timing), median with a bootstrap
  95 % interval and p95 in ms over scans with status `ok` or `failed`. The wall time is shown
  beside it; on a shared machine it is inflated by other processes, CPU time far less.
- **Intervals**: success rates with Wilson 95 % score intervals; medians with percentile
  bootstrap 95 % intervals (2000 resamples, seeded). Written as `value [low–high]`.
- **Paired comparisons**: every pair of matchers on the scans both answered (with truth); an
  exact McNemar test on success (binomial test of the scans where only one succeeded) and a
  paired bootstrap 95 % interval of the success-rate difference. P-values are Holm-adjusted
  within each table (all pairs on one dataset, or pooled); significant = adjusted p < {ALPHA:g}.
- **Bins** come from the true and initial poses (not from group labels): initial distance offset
  [0, 100), [100, 200), [200, 300), [300, ∞) cm; initial angle offset [0, 5), [5, 10), [10, 15),
  [15, ∞) degrees. Left edge included: an offset of exactly 100 cm is in 100–200.
- **Scenarios** (the paper's Section 5): {_scenario_definition(paper or {})}.
- Published values: {CITATION}. The paper's tables give no success rates, medians or runtimes.
"""
