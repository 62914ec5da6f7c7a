"""The rows of the tracking tables: ``tracking.csv`` (every score per sequence and tracker),
``kidnap.csv``, ``start.csv`` and ``selfassess.csv`` (metres, degrees, milliseconds, fractions
as their names say)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, make_dataclass


@dataclass(frozen=True)
class TrackScore:
    """The scores of one tracked sequence (:mod:`tfloc.evaluation.trajectory`): scans and those
    with truth, the distance driven (m), the tracked share (fraction) and count, losses,
    recoveries and the unrecovered, the longest stretch lost (m), evo's APE (m; rotation in °)
    and RPE (per metre driven), the median CPU per step (ms), the largest jump (m) and the jumps
    beyond 1 m."""

    n_scans: int
    n_truth: int
    distance_m: float
    tracked: float
    n_tracked: int
    losses: int
    recoveries: int
    unrecovered: int
    longest_lost_m: float
    ape_rmse_m: float
    ape_mean_m: float
    ape_max_m: float
    ape_rot_rmse_deg: float
    ape_rot_max_deg: float
    rpe_trans_m_per_m: float
    rpe_rot_deg_per_m: float
    cpu_ms_median: float
    max_jump_m: float = math.nan
    jumps: int = 0

    def to_dict(self) -> dict[str, float]:
        return asdict(self)


#: one row of ``tracking.csv``: the sequence, the tracker, its condition (the sequence's set),
#: then every field of :class:`TrackScore`
TrackingRow = make_dataclass(
    "TrackingRow", [("dataset", str), ("matcher", str), ("condition", str)]
    + [(f.name, f.type, f) for f in fields(TrackScore)], frozen=True)
TrackingRow.__module__ = __name__


@dataclass(frozen=True)
class KidnapRow:
    """One kidnap event of a tracker on a sequence: its set, the kidnap scan, scans to
    relocalize (NaN: never) and, on each (sequence, tracker)'s first event, its false
    relocalizations and tracked share (NaN on the others)."""

    dataset: str
    matcher: str
    set: str
    kidnap_scan: str
    scans_to_relocalize: float
    false_relocalizations: int
    tracked: float


@dataclass(frozen=True)
class StartRow:
    """A tracker's start on a sequence of a set where some tracker starts without a pose: whether
    it did, the start window (scans), scans to converge and the scan it first settled at (NaN:
    never), and whether that place was wrong."""

    dataset: str
    matcher: str
    set: str
    no_pose: bool
    window: int
    scans_to_converge: float
    settled: float
    settled_wrong: bool


@dataclass(frozen=True)
class SelfAssessment:
    """One tracker's lost-detector on one scope (a dataset, or ``all`` pooled): its confidence's
    ``key``, scans with truth and with a value, lost scans among them, AUC and the share caught
    at 1 % false alarms (fractions)."""

    scope: str
    matcher: str
    key: str
    scans: int
    lost: int
    auc: float
    caught: float
