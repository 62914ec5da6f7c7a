"""Every table file of a run directory, once: its name, its row type
(:mod:`tfloc.core.rows`) and the format of its numbers. :class:`~tfloc.io.rundir.RunDir` reads
and writes them through the one codec (:mod:`tfloc.io.table`); ``estimates.csv`` (the rows) has
its own append-only writer (:mod:`tfloc.io.estimates`)."""

from __future__ import annotations

from tfloc.core.rows.headline import HeadlineRow
from tfloc.core.rows.relocalization import GlobalSummary
from tfloc.core.rows.robustness import RobustnessRow
from tfloc.core.rows.scaling import LevelRow, SlopeRow
from tfloc.core.rows.summary import GuardRow, GuardTrackingRow, PairedRow, SummaryRow
from tfloc.core.rows.timing import PrepRow, ScanRow, SkipRow, TimingRow
from tfloc.core.rows.tracking import KidnapRow, SelfAssessment, StartRow, TrackingRow
from tfloc.core.rows.verdict import (
    Agreement,
    FlagRow,
    SweepRow,
    TrackerCheck,
    VerdictRow,
    VerdictScanRow,
)

from .table import Table

HEADLINE = Table("headline.csv", HeadlineRow, "headline table")
SUMMARY = Table("summary.csv", SummaryRow, "summary table")
PAIRED = Table("paired.csv", PairedRow, "paired comparisons")
TRACKING = Table("tracking.csv", TrackingRow, "tracking scores")
KIDNAP = Table("kidnap.csv", KidnapRow, "kidnap events")
START = Table("start.csv", StartRow, "starts without a pose")
SELFASSESS = Table("selfassess.csv", SelfAssessment, "self-assessments")
RELOCALIZATION = Table("relocalization.csv", GlobalSummary, "global localization scores")
VERDICT = Table("verdict.csv", VerdictRow, "truth-free verdict")
VERDICT_SCANS = Table("verdict_scans.csv.gz", VerdictScanRow, "truth-free verdict per scan", "%.5g")
VERDICT_CHECKS = Table("verdict_checks.csv", TrackerCheck, "truth-free verdict against the truth")
VERDICT_AGREEMENT = Table("verdict_agreement.csv", Agreement, "truth-free ranking against the truth's")
VERDICT_FLAGS = Table("verdict_flags.csv", FlagRow, "flagged stretches of the recordings")
VERDICT_SWEEP = Table("verdict_sweep.csv", SweepRow, "verdict configurations against the truth")
ROBUSTNESS = Table("robustness.csv", RobustnessRow, "robustness cells", "%.4g")
TIMING = Table("timing.csv", TimingRow, "timing pass", "%.4f")
SCALING = Table("scaling.csv", ScanRow, "scaling study's timings")
PREP = Table("prep.csv", PrepRow, "scaling study's preparations")
SKIPS = Table("skips.csv", SkipRow, "scaling study's skipped levels")
LEVELS = Table("levels.csv", LevelRow, "scaling levels")
SLOPES = Table("slopes.csv", SlopeRow, "scaling slopes", "%.4g")
GUARD = Table("summary.csv", GuardRow, "regression guard reference")
GUARD_TRACKING = Table("tracking.csv", GuardTrackingRow, "tracking guard reference")

#: the truth-free verdict's files (removed together when it is made again or discarded)
VERDICT_FILES = (VERDICT, VERDICT_SCANS, VERDICT_CHECKS, VERDICT_AGREEMENT, VERDICT_FLAGS)
