"""A headline row: one matcher's line of a run's headline table (``headline.csv``; computed by
:func:`tfloc.evaluation.headline.headline`, read by the report, the site and the README)."""

from __future__ import annotations

import math
from dataclasses import dataclass

#: the scope of a table pooled over a mode's datasets
POOLED = "all"


@dataclass(frozen=True)
class HeadlineRow:
    """One matcher's line of a headline table (percentages in %, errors in cm, CPU in ms):
    its ``rank`` within (``mode``, ``scope``), the ``measure`` and its 95 % interval over ``n``
    scans, the ``error`` named, the median CPU, the paired ``verdict`` against ``next_matcher``
    (``ahead``, ``tied`` or empty) with its Holm-adjusted p; a tracking row's truth-free score and
    self-assessment AUC (NaN where not computed)."""

    mode: str
    scope: str
    rank: int
    matcher: str
    measure: str
    value_pct: float
    lo_pct: float
    hi_pct: float
    n: int
    error_cm: float
    error: str
    cpu_ms: float
    verdict: str
    next_matcher: str
    p_holm: float
    truth_free_score: float = math.nan
    self_auc: float = math.nan
