"""The published results of the turning-function paper, for side-by-side comparison.

Source: "Optimal Robot Pose Estimation Using Scan Matching by Turning Function" (MDPI,
Mathematics), Section 5, Table 2 (Scenario I: environmental detail levels 1–3), Table 3
(Scenario II: initial angle offset 0–5°, 5–10°, 10–15°, 540 scans each) and Table 4
(Scenario III: initial distance offset 0–100, 100–200, 200–300 cm, 540 scans each).
Values as printed: mean distance error (cm), mean orientation error (°), distance and
orientation improvement (%). The paper does not state how its "improvement" averages over
scans; tfloc reports the mean of per-scan values (see :mod:`tfloc.evaluation.metrics`).
"""

from __future__ import annotations

from dataclasses import dataclass

CITATION = ('"Optimal Robot Pose Estimation Using Scan Matching by Turning Function", '
            "Mathematics (MDPI), Section 5, Tables 2–4")


@dataclass(frozen=True)
class PaperRow:
    """One row of Tables 2–4: the ``key`` is the tfloc sample (dataset or bin label) it matches."""

    scenario: str          # "I", "II" or "III"
    label: str             # the paper's row label (1, 2, 3)
    key: str               # tfloc dataset name (I) or bin label (II: angle_bin, III: dist_bin)
    sample: int | None     # number of scans the paper states (None: not given)
    dist_err_cm: float
    orient_err_deg: float
    dist_impr_pct: float
    orient_impr_pct: float


PAPER_TF: tuple[PaperRow, ...] = (
    PaperRow("I", "1", "detail-1", None, 7.7878, 1.0526, 94.8979, 82.8125),
    PaperRow("I", "2", "detail-2", None, 7.9858, 0.6315, 64.3136, 90.6250),
    PaperRow("I", "3", "detail-3", None, 9.3984, 0.8421, 93.0935, 88.2353),
    PaperRow("II", "1", "0–5", 540, 8.5752, 0.4368, 94.2968, 77.4194),
    PaperRow("II", "2", "5–10", 540, 6.5290, 0.7371, 95.3235, 86.2746),
    PaperRow("II", "3", "10–15", 540, 10.0688, 1.0536, 92.7747, 90.5661),
    PaperRow("III", "1", "0–100", 540, 6.0639, 0.4210, 89.8533, 93.7500),
    PaperRow("III", "2", "100–200", 540, 8.6486, 1.0538, 93.9186, 84.6154),
    PaperRow("III", "3", "200–300", 540, 10.4595, 1.0526, 95.5024, 85.5073),
)
TABLE_OF = {"I": 2, "II": 3, "III": 4}


def paper_row(scenario: str, key: str) -> PaperRow | None:
    """The published row for a scenario and tfloc sample key, if the paper has one."""
    return next((r for r in PAPER_TF if r.scenario == scenario and r.key == key), None)
