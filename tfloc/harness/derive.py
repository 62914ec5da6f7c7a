"""The tables a run's rows derive, computed once and written through the store.

``tfloc report RUN`` (and a study's ``report`` step) first derives, then draws
(:mod:`tfloc.report.report`). :func:`derive` reads the rows and ``run.json``, scores them
(:mod:`tfloc.evaluation`: pure) and writes, as the run's datasets call for: ``headline.csv``
(every mode and scope, the one headline the report, the site and the README read),
``summary.csv`` and ``paired.csv`` (single-scan and scan-to-scan datasets), ``tracking.csv``,
``kidnap.csv``, ``start.csv`` and ``selfassess.csv`` (sequences), ``relocalization.csv``
(global datasets). A table a run no longer calls for is removed. The truth-free verdict
(``tfloc verdict``, :mod:`tfloc.harness.verdict`) is read where it judged the current rows.

``run.json``'s ``derived.tables`` records what they were made from: the identity of this
module's import closure (:func:`tfloc.harness.identity.derived_code`) and the hashes of the
rows and of the verdict; :func:`stale` says why recorded tables are not current. They are
re-made from the rows, never by running a matcher again.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from tfloc.core.modes import GLOBAL, SCAN_TO_SCAN, SEQUENCE
from tfloc.core.rows.headline import HeadlineRow
from tfloc.core.rows.tracking import SelfAssessment
from tfloc.core.run import DerivedRecord, RunRecord
from tfloc.core.thresholds import Thresholds
from tfloc.errors import TflocError
from tfloc.evaluation.headline import Extras, Verdicts, headline
from tfloc.evaluation.metrics import prepare
from tfloc.evaluation.paired import MANY_MATCHERS, paired_table
from tfloc.evaluation.relocalization import free_area_m2, result_from_row, summarize
from tfloc.evaluation.robustness import axes_of, paired_changes, robustness_cells
from tfloc.evaluation.selfassess import self_assessments
from tfloc.evaluation.sequences import kidnap_events, sequence_scores, start_scores
from tfloc.evaluation.summary import summary_table
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import Scenario, load_dataset, read_scenario
from tfloc.io.tables import (
    HEADLINE,
    KIDNAP,
    PAIRED,
    RELOCALIZATION,
    ROBUSTNESS,
    SELFASSESS,
    START,
    SUMMARY,
    TRACKING,
    VERDICT,
    VERDICT_SCANS,
)

from .identity import derived_code
from .workspace import map_of

PRODUCER = "tables"


@dataclass(frozen=True)
class TruthFree:
    """What the tables take from the truth-free verdict: per-scan beliefs (``dataset, scan_id,
    matcher, believed``; ``None`` without a current verdict), the verdict's score per (scope,
    matcher), and a note (why there is no verdict, or ``""``)."""

    beliefs: pd.DataFrame | None = None
    free: Verdicts = field(default_factory=dict)
    note: str = ""


@dataclass(frozen=True)
class Derived:
    """A run's rows and record with the tables derived from them (the report draws these)."""

    rows: pd.DataFrame
    record: RunRecord
    thresholds: Thresholds
    prepared: pd.DataFrame
    headline: list[HeadlineRow]
    scenarios: dict[str, Scenario]
    maps: dict[str, object]
    assessments: list[SelfAssessment]
    truth_free: TruthFree
    sequences: frozenset[str]
    globals_: frozenset[str]
    sweep: bool = False


def verdict_note(rd: RunDir, record: RunRecord) -> str:
    """``""`` when the run has a truth-free verdict of its current rows, else why not."""
    if not rd.has(VERDICT):
        return "no truth-free verdict yet (tfloc verdict RUN)"
    judged = record.verdict.rows_sha256 if record.verdict is not None else None
    if rd.estimates.is_file() and judged not in (None, rd.rows_sha256()):
        return "the verdict judged other rows than the run's (tfloc verdict RUN)"
    return ""


def truth_free(rd: RunDir, record: RunRecord) -> TruthFree:
    """The run's current truth-free verdict, as the headline takes it."""
    note = verdict_note(rd, record)
    if note:
        return TruthFree(note=note)
    v = rd.frame(VERDICT)
    free = {(str(r.dataset), str(r.matcher)): (float(r.score_pct), float(r.lo_pct), float(r.hi_pct))
            for r in v.itertuples()}
    beliefs = rd.frame(VERDICT_SCANS)[["dataset", "scan_id", "matcher", "believed"]] \
        if rd.has(VERDICT_SCANS) else None
    return TruthFree(beliefs, free, "")


def _datasets(record: RunRecord, names: set[str]) -> tuple[dict[str, Scenario], dict[str, object]]:
    """The scenarios and maps of the run's datasets ``names`` that are on disk."""
    scenarios, maps = {}, {}
    for n, d in record.paths.items():
        if n not in names:
            continue
        try:
            scenario, scans = load_dataset(str(d))
        except TflocError:
            continue
        scenarios[n] = scenario
        if scans:
            maps[n] = map_of(scenario, next(iter(scans.values())))
    return scenarios, maps


def label_order(record: RunRecord, p: pd.DataFrame) -> list[str]:
    """The run's matcher labels in the order of its configuration (sorted without run.json)."""
    present = set(p["matcher"])
    return [m for m in record.labels if m in present] or sorted(present)


def derive(run_dir: str | Path, thresholds: Thresholds | None = None) -> Derived:
    """Derive and write the tables of the run in ``run_dir`` (module notes); ``thresholds``
    re-scores the rows under other thresholds than the run's."""
    rd = RunDir(Path(run_dir))
    rd.require_results()
    df, record = rd.results(), rd.info()
    thr = thresholds or record.thresholds
    names = list(df["dataset"].unique())
    seq, glob = record.datasets_in(names, SEQUENCE.key), record.datasets_in(names, GLOBAL.key)
    prepared = prepare(df, thr)
    scenarios, maps = _datasets(record, seq | glob)
    extras = {n: sc.extra for n, sc in scenarios.items()}
    tf = truth_free(rd, record) if seq else TruthFree()
    assessments = self_assessments(prepared, sorted(seq), thr) if seq else []
    auc: Extras = {(a.scope, a.matcher): a.auc for a in assessments}
    rows = headline(prepared, {n: record.mode(n) for n in names}, thr, tf.beliefs, tf.free, auc)
    written = {HEADLINE: rows, SELFASSESS: assessments}
    if seq:
        s = df[df["dataset"].isin(seq)]
        scored = s[s["true_x"].notna().groupby(s["dataset"]).transform("any")]
        written[TRACKING] = sequence_scores(s, extras, thr)
        written[KIDNAP] = kidnap_events(scored, extras, thr)
        written[START] = start_scores(scored, extras, thr)
    if glob:
        g = df[df["dataset"].isin(glob)]
        results = [r for r in (result_from_row(x, thr, f"{x['dataset']}/{x['scan_id']}")
                               for x in g.to_dict("records")) if r]
        written[RELOCALIZATION] = summarize(results, {d: free_area_m2(m) for d, m in maps.items() if d in glob})
    single = prepared[~prepared["dataset"].isin(seq | glob)]
    sweep = False
    if len(single):
        s2s = record.datasets_in(list(single["dataset"].unique()), SCAN_TO_SCAN.key)
        paper = {d: s for d, s in record.paper_scenarios().items() if d in set(single["dataset"])}
        order = label_order(record, single)
        sweep = len(order) > MANY_MATCHERS
        written[SUMMARY] = summary_table(single, s2s, paper)
        written[PAIRED] = paired_table(single, s2s, reference=order[0] if sweep else None)
    for table in (HEADLINE, SUMMARY, PAIRED, TRACKING, KIDNAP, START, SELFASSESS, RELOCALIZATION):
        items = written.get(table)
        if items is not None and len(items):
            rd.write(table, items)
        else:
            rd.remove(table)
    rd.record_derived(PRODUCER, DerivedRecord(derived_code(__name__), rd.rows_sha256(), rd.table_sha256(VERDICT)))
    return Derived(df, record, thr, prepared, rows, scenarios, maps, assessments, tf, frozenset(seq),
                   frozenset(glob), sweep)


def stale(run_dir: str | Path) -> list[str]:
    """Why a run's derived tables are not those its rows and this code make, one phrase each;
    empty when they are current (a run without rows: nothing to derive)."""
    rd = RunDir(Path(run_dir))
    if not rd.has_rows():
        return []
    rec = rd.info().derived.get(PRODUCER)
    if rec is None:
        return ["its tables record nothing they were derived from (tfloc report RUN)"]
    out = []
    if rec.code != derived_code(__name__):
        out.append("the code that derives them changed")
    if rec.rows_sha256 != rd.rows_sha256():
        out.append("the run's rows changed")
    if rec.verdict_sha256 != rd.table_sha256(VERDICT):
        out.append("the truth-free verdict changed")
    return out


def derive_robustness(run_dir: str | Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The robustness cells (written to ``robustness.csv``) and the paired changes of a run whose
    datasets declare their place on the map-style axes (:mod:`tfloc.evaluation.robustness`)."""
    rd = RunDir(Path(run_dir))
    info = rd.info(required=True)
    axes = axes_of((s.name, s.extra) for s in (read_scenario(d) for d in info.paths.values()))
    prepared = prepare(rd.results(), info.thresholds)
    rd.write(ROBUSTNESS, robustness_cells(prepared, axes))
    return rd.frame(ROBUSTNESS), paired_changes(prepared, axes)
