"""The tables of tracked sequences, from a run's rows: every score per (sequence, tracker)
(``tracking.csv``), each kidnap event (``kidnap.csv``) and each start without a pose
(``start.csv``).

Input: the estimate rows of sequence datasets (one row per scan and tracker, each (dataset,
tracker)'s rows in scan order as the tracking loop writes them) and, per dataset, what its
``scenario.json`` declares (``extras``: its ``set`` or ``condition.name``, its ``kidnaps``). A
**sequence set** is the datasets of one condition (``set``, else ``condition.name``: easy,
rate-1hz, …, real; else the rows' group). Definitions: :mod:`tfloc.evaluation.trajectory`,
:mod:`tfloc.evaluation.kidnap`, :mod:`tfloc.evaluation.global_start`. Metres, radians, ms.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from tfloc.core.rows.tracking import KidnapRow, StartRow, TrackingRow
from tfloc.core.thresholds import Thresholds

from .global_start import score_start, starts_without_pose
from .kidnap import score_kidnaps
from .trajectory import score_rows

DEFAULT = Thresholds()
Extras = Mapping[str, Mapping]


def poses(g: pd.DataFrame, prefix: str) -> np.ndarray:
    """The ``(N, 3)`` poses ``<prefix>_x/_y/_theta`` of estimate rows (metres, radians; NaN where
    empty)."""
    return g[[f"{prefix}_x", f"{prefix}_y", f"{prefix}_theta"]].to_numpy(float)


def condition_of(extra: Mapping | None, rows: pd.DataFrame) -> str:
    """The sequence set of a dataset: its ``set``, else its ``condition.name``, else its rows'
    group."""
    extra = extra or {}
    return str(extra.get("set") or (extra.get("condition") or {}).get("name") or rows["group"].iloc[0])


def sequence_scores(df: pd.DataFrame, extras: Extras, thresholds: Thresholds = DEFAULT) -> list:
    """One :class:`~tfloc.core.rows.tracking.TrackingRow` per (dataset, tracker): its condition
    and every score of :class:`~tfloc.core.rows.tracking.TrackScore`."""
    out = []
    for (ds, m), g in df.groupby(["dataset", "matcher"], sort=False):
        s = score_rows(g, thresholds).to_dict()
        out.append(TrackingRow(dataset=ds, matcher=m, condition=condition_of(extras.get(ds), g), **s))
    return out


def _positions(g: pd.DataFrame, ids) -> list[int]:
    pos = {str(sid): i for i, sid in enumerate(g["scan_id"].astype(str))}
    return [pos[k] for k in map(str, ids or []) if k in pos]


def kidnap_events(df: pd.DataFrame, extras: Extras, thresholds: Thresholds = DEFAULT) -> list[KidnapRow]:
    """One row per (kidnapped dataset, tracker, event): its set, the kidnap scan, scans to
    relocalize (NaN = never) and, on each (dataset, tracker)'s first event row, its false
    relocalizations and tracked share."""
    out = []
    for (ds, m), g in df.groupby(["dataset", "matcher"], sort=False):
        extra = extras.get(ds) or {}
        events = _positions(g, extra.get("kidnaps"))
        if not events:
            continue
        ks = score_kidnaps(poses(g, "est"), poses(g, "true"), poses(g, "init"), events, thresholds)
        tracked = score_rows(g, thresholds).tracked
        for i, (e, n) in enumerate(zip(ks.events, ks.scans_to_relocalize, strict=True)):
            out.append(KidnapRow(ds, m, condition_of(extra, g), str(g["scan_id"].iloc[e]),
                                 math.nan if n is None else n, len(ks.false_relocalizations) if i == 0 else 0,
                                 tracked if i == 0 else math.nan))
    return out


def start_scores(df: pd.DataFrame, extras: Extras, thresholds: Thresholds = DEFAULT) -> list[StartRow]:
    """One row per (dataset, tracker) of a set where some tracker starts without a pose: its set,
    whether it did (``info["start"]`` of its first row), the start window (to the first kidnap
    scan, else the end), scans to converge (NaN = never), the scan it first settled at and
    whether that place was wrong. None when no tracker starts without a pose."""
    out = []
    for (ds, m), g in df.groupby(["dataset", "matcher"], sort=False):
        extra = extras.get(ds) or {}
        kid = _positions(g, extra.get("kidnaps"))
        st = score_start(poses(g, "est"), poses(g, "true"), min(kid, default=len(g)), thresholds)
        first = g["info"].iloc[0] if "info" in g else ""
        out.append(StartRow(ds, m, condition_of(extra, g),
                            starts_without_pose(json.loads(first) if isinstance(first, str) and first else {}),
                            st.window, math.nan if st.scans_to_converge is None else st.scans_to_converge,
                            math.nan if st.settled is None else st.settled, bool(st.wrong)))
    sets = {r.set for r in out if r.no_pose}
    return [r for r in out if r.set in sets]
