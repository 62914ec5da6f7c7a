"""The row of ``robustness.csv``: one matcher on one map style of one real log."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class RobustnessRow:
    """One matcher on one log's map ``style``: scans ``n``, successes ``k``, the success rate (%)
    with its Wilson interval, the median distance error (cm) and the median CPU (ms)."""

    matcher: str
    log: str
    style: str
    n: int
    k: int
    rate: float
    lo: float
    hi: float
    median_cm: float
    cpu_ms: float
