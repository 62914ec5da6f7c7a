"""The row of ``relocalization.csv``: one global matcher on one global dataset."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class GlobalSummary:
    """Global localization of one matcher on one dataset.

    Rates are fractions in [0, 1] with Wilson 95 % intervals; ``ambiguous`` is the share of the
    scans whose (wrong) answer the matcher's own score prefers to the truth; ``cpu_ms_median`` is
    CPU milliseconds per scan; ``ms_per_100m2`` the median cost per 100 m² of free area."""

    dataset: str
    matcher: str
    n: int
    top1: float
    top1_lo: float
    top1_hi: float
    top5: float
    top5_lo: float
    top5_hi: float
    ambiguous: float
    no_answer: float
    cpu_ms_median: float
    free_area_m2: float
    ms_per_100m2: float
    place_recall1: float = math.nan  # NaN: the matcher records no places
    place_recall5: float = math.nan
    place_recall_all: float = math.nan
