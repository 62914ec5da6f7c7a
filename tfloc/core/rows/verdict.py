"""The rows of the truth-free verdict's files (``tfloc verdict RUN``): ``verdict.csv``,
``verdict_scans.csv.gz``, ``verdict_checks.csv``, ``verdict_agreement.csv``,
``verdict_flags.csv`` and ``verdict_sweep.csv`` (percentages in %, counts of scans)."""

from __future__ import annotations

from dataclasses import dataclass, fields, make_dataclass

#: the scope of a verdict pooled over a run's recordings
POOLED = "all"


@dataclass(frozen=True)
class VerdictRow:
    """One tracker's truth-free verdict on one recording (percentages in %, counts of scans).

    ``score_pct`` [``lo_pct``, ``hi_pct``]: the believed-tracked share and its interval;
    ``consensus_pct``: scans where the others had a consensus; ``agree_pct``: of those, the share
    it agreed with; ``fit_pct``: its mean fit share; ``odometry_pct``: scans whose correction
    disagrees with the odometry; ``jumps``: corrections beyond the jump limit;
    ``reconverged_pct``: restarts that came back (of ``restarts``; NaN where none ran)."""

    dataset: str
    matcher: str
    score_pct: float
    lo_pct: float
    hi_pct: float
    scans: int
    consensus_pct: float
    agree_pct: float
    fit_pct: float
    odometry_pct: float
    jumps: int
    reconverged_pct: float
    restarts: int


@dataclass(frozen=True)
class VerdictScanRow:
    """One scan of one tracker as the verdict judged it: inside a flagged stretch of the
    recording (0/1), its fit share and the best of any tracker's, the consensus there
    (``agree``, ``disagree`` or ``none``) and its support, its correction (m, rad), whether the
    odometry disagrees (0/1) and whether it is believed tracked (0/1)."""

    dataset: str
    scan_id: str
    matcher: str
    flagged: int
    fit: float
    best_fit: float
    consensus: str
    support: float
    correction_m: float
    correction_rad: float
    odometry_disagrees: int
    believed: int


@dataclass(frozen=True)
class TrackerCheck:
    """One tracker's verdict against the truth on one recording (% and scans with truth)."""

    dataset: str
    matcher: str
    score_pct: float
    truth_pct: float
    truth_scans: int
    wrong: int
    missed_losses: int
    false_alarms: int


@dataclass(frozen=True)
class Agreement:
    """The verdict's ranking against the truth's on one recording: trackers judged, Spearman's
    rho, the two tops, whether they are the ``same``, ``tied`` (the paired test does not separate
    them) or ``different`` (with the test's p), the scans judged wrongly (%), missed losses and
    false alarms, and whether the verdict agrees with the truth."""

    dataset: str
    trackers: int
    rho: float
    truth_top: str
    verdict_top: str
    top: str
    p_top: float
    wrong_pct: float
    missed_losses: int
    false_alarms: int
    agrees: bool


@dataclass(frozen=True)
class FlagRow:
    """One flagged stretch of a recording (:mod:`tfloc.evaluation.recording`): its kind, first
    and last scan ids, scans, duration (s; NaN without stamps) and the message."""

    dataset: str
    kind: str
    first: str
    last: str
    scans: int
    duration_s: float
    message: str


#: one row of ``verdict_sweep.csv``: the configuration changed, then an :class:`Agreement`
SweepRow = make_dataclass("SweepRow", [("config", str)] + [(f.name, f.type, f) for f in fields(Agreement)],
                          frozen=True)
SweepRow.__module__ = __name__
