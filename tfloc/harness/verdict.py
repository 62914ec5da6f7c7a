"""``tfloc verdict RUN``: the truth-free verdict of a run's sequence datasets, written beside it.

For every sequence dataset of the run, the trackers' answers (``estimates.csv``), the dataset's
scans, odometry and map are judged without the truth (:mod:`tfloc.evaluation.truthfree`), the
re-convergence restarts are run (:mod:`tfloc.harness.restarts`), and four files are written:

* ``verdict.csv``: per (dataset, tracker) and pooled (``all``), the verdict and every signal
  (:class:`~tfloc.evaluation.truthfree.judge.VerdictRow`);
* ``verdict_scans.csv.gz``: per scan and tracker, the signals and the belief;
* ``verdict_checks.csv`` and ``verdict_agreement.csv`` (datasets with truth only): the verdict
  against the truth, per tracker and per recording (:mod:`tfloc.evaluation.truthfree.agreement`);
* ``verdict_flags.csv``: each recording's flagged stretches (odometry stalls, jumps and gaps, scan
  gaps, empty scans: :mod:`tfloc.evaluation.recording`, as ``tfloc check-recording`` finds them);
  a scan inside one is marked ``flagged`` in the per-scan table, and the report names them.

The truth is read only after the verdict is made, to check it. ``run.json`` records the
verdict's configuration and the hash of the rows it judged (``verdict``), so a report can tell
a verdict of other rows.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from tfloc.core.rows.verdict import POOLED, Agreement, FlagRow, TrackerCheck, VerdictRow
from tfloc.core.run import RunMatcher, RunRecord
from tfloc.core.traits import method_of
from tfloc.errors import ResultsError
from tfloc.evaluation.metrics import tracked as tracked_rows
from tfloc.evaluation.recording import check_recording
from tfloc.evaluation.sequences import poses
from tfloc.evaluation.trajectory import pooled_share
from tfloc.evaluation.truthfree import reconverge as R
from tfloc.evaluation.truthfree.agreement import agreement, tracker_checks
from tfloc.evaluation.truthfree.config import TruthFreeConfig
from tfloc.evaluation.truthfree.judge import Judgement, judge, verdict_rows
from tfloc.evaluation.truthfree.mapfit import fit_shares, scan_points
from tfloc.io.rundir import RunDir, VerdictRecord
from tfloc.io.scenario import SEQUENCE, load_dataset
from tfloc.io.tables import VERDICT, VERDICT_AGREEMENT, VERDICT_CHECKS, VERDICT_FLAGS, VERDICT_SCANS
from tfloc.maps.fields import distance_field

from .identity import derived_code
from .restarts import restart_ends
from .workspace import load_matcher, map_of

DEFAULT = TruthFreeConfig()


@dataclass(frozen=True)
class Recording:
    """One sequence dataset of a run, ready to judge: its trackers (run order) and ``(M, N, 3)``
    answers and predictions, its scans in order, whether each has truth and which trackers were
    tracked there (``(M, N)``, False without truth)."""

    name: str
    matchers: list[str]
    est: np.ndarray
    init: np.ndarray
    scan_ids: list[str]
    has_truth: np.ndarray
    tracked: np.ndarray


def recording(df: pd.DataFrame, name: str, order: list[str], scan_ids: list[str], thr) -> Recording:
    """The :class:`Recording` of dataset ``name`` from a run's rows (trackers without a row for
    every scan are left out: an interrupted sequence is not judged)."""
    d = df[df["dataset"] == name]
    labels, est, init, tracked = [], [], [], []
    truth = None
    for m in order:
        g = d[d["matcher"] == m].set_index("scan_id")
        if len(g) != len(scan_ids) or not g.index.isin(scan_ids).all():
            continue
        g = g.loc[scan_ids]
        labels.append(m)
        est.append(poses(g, "est"))
        init.append(poses(g, "init"))
        tracked.append(tracked_rows(g, thr))
        if truth is None:
            truth = g["true_x"].notna().to_numpy(bool)
    n = len(scan_ids)
    shape = (len(labels), n)
    return Recording(name, labels, np.array(est).reshape(*shape, 3), np.array(init).reshape(*shape, 3),
                     scan_ids, truth if truth is not None else np.zeros(n, bool),
                     np.array(tracked, dtype=bool).reshape(shape))


@dataclass(frozen=True)
class Verdict:
    """What :func:`judge_run` found: the verdict rows (per dataset and pooled), the per-scan
    table, and against the truth the per-tracker checks and per-recording agreements."""

    rows: list[VerdictRow]
    scans: pd.DataFrame
    checks: list[TrackerCheck]
    agreements: list[Agreement]
    flags: list[FlagRow] = field(default_factory=list)


def _order(info: RunRecord, df: pd.DataFrame) -> list[str]:
    labels = info.labels
    present = set(df["matcher"])
    return [m for m in labels if m in present] or sorted(present)


def _restarts(scenario, scans, rec: Recording, specs: dict[str, RunMatcher], the_map, cfg: TruthFreeConfig,
              log: Callable[[str], None]) -> dict[str, np.ndarray]:
    """Per tracker, whether each of its restarts returned (:mod:`~tfloc.evaluation.truthfree.reconverge`)."""
    plan = R.plan(len(scans), cfg.restarts, cfg.restart_scans, cfg.restart_offset_m, cfg.restart_offset_rad,
                  cfg.seed)
    out: dict[str, np.ndarray] = {}
    if not plan:
        return out
    last = np.array([r.last for r in plan])
    for i, m in enumerate(rec.matchers):
        spec = specs.get(m) or RunMatcher(m, m, m)
        try:
            matcher = load_matcher(spec.name, spec.params_json)
        except Exception as exc:  # noqa: BLE001 - a tracker that cannot be built is reported, not fatal
            log(f"{rec.name}: {m}: no restarts ({type(exc).__name__}: {exc})")
            continue
        ends = restart_ends(scenario, scans, matcher, rec.est[i], plan, the_map)
        out[m] = R.returned(ends, rec.est[i][last], cfg.agree_m, cfg.agree_rad)
    return out


def _scan_table(rec: Recording, j: Judgement, flagged: np.ndarray) -> pd.DataFrame:
    m, n = j.believed.shape
    state = np.where(j.known, np.where(j.agree, "agree", "disagree"), "none")
    return pd.DataFrame({
        "dataset": rec.name, "scan_id": np.tile(rec.scan_ids, m), "matcher": np.repeat(rec.matchers, n),
        "flagged": np.tile(flagged.astype(int), m),
        "fit": j.fit.ravel(), "best_fit": np.tile(j.best_fit, m), "consensus": state.ravel(),
        "support": j.support.ravel(), "correction_m": j.dist.ravel(), "correction_rad": j.turn.ravel(),
        "odometry_disagrees": j.odometry_disagrees.ravel().astype(int), "believed": j.believed.ravel().astype(int)})


def pooled_rows(rows: list[VerdictRow], beliefs: dict[tuple[str, str], np.ndarray]) -> list[VerdictRow]:
    """Each tracker's verdict pooled over the run's recordings (the share over every scan, its
    interval a bootstrap over recordings, :func:`~tfloc.evaluation.trajectory.pooled_share`;
    the other signals weighted by scans); only with more than one recording."""
    if len({r.dataset for r in rows}) < 2:
        return []
    out = []
    for m in dict.fromkeys(r.matcher for r in rows):
        mine = [r for r in rows if r.matcher == m]
        k = [float(beliefs[(r.dataset, m)].sum()) for r in mine]
        n = [r.scans for r in mine]
        s, lo, hi = pooled_share(k, n)
        w = np.array(n, dtype=float)

        def avg(field: str, rows_=mine, w=w) -> float:
            v = np.array([getattr(r, field) for r in rows_], dtype=float)
            ok = np.isfinite(v)
            return float(np.average(v[ok], weights=w[ok])) if ok.any() else math.nan

        restarts = sum(r.restarts for r in mine)
        back = sum(r.reconverged_pct / 100 * r.restarts for r in mine if r.restarts)
        out.append(VerdictRow(POOLED, m, 100 * s, 100 * lo, 100 * hi, int(sum(n)), avg("consensus_pct"),
                              avg("agree_pct"), avg("fit_pct"), avg("odometry_pct"), sum(r.jumps for r in mine),
                              100 * back / restarts if restarts else math.nan, restarts))
    return out


def judge_run(run_dir: str | Path, cfg: TruthFreeConfig = DEFAULT, restarts: bool = True,
              log: Callable[[str], None] = print) -> Verdict:
    """The truth-free verdict of every sequence dataset of the run in ``run_dir`` (module notes)."""
    rd = RunDir(Path(run_dir))
    df, info = rd.results(), rd.info()
    names = [n for n in df["dataset"].unique() if n in info.datasets_in(list(df["dataset"].unique()), SEQUENCE)]
    if not names:
        raise ResultsError(f"{run_dir}: no sequence dataset: the truth-free verdict judges trackers along "
                           "recordings (tfloc bench on a sequence dataset first)")
    order, thr = _order(info, df), info.thresholds
    specs = {m.label: m for m in info.matchers}
    rows, tables, checks, agreements, beliefs, flags = [], [], [], [], {}, []
    for name in names:
        scenario, by_id = load_dataset(str(info.paths[name]))
        scans = list(by_id.values())
        rec = recording(df, name, order, [s.scan_id for s in scans], thr)
        if not rec.matchers:
            log(f"{name}: no tracker has a row for every scan: not judged")
            continue
        check = check_recording(scans, scenario.laser)
        flagged = np.zeros(len(scans), bool)
        for f in check.flags:
            flagged[f.first:f.last + 1] = True
            flags.append(FlagRow(name, f.kind, f.first_id, f.last_id, f.scans, f.duration_s, f.message))
        the_map = map_of(scenario, scans[0])
        field = distance_field(the_map, cfg.field_resolution_m, cap=4 * cfg.fit_tol_m, pad=1.0)
        points = scan_points(np.stack([s.ranges for s in scans]), scenario.laser)
        fit = np.stack([fit_shares(points, rec.est[i], field, cfg.fit_tol_m) for i in range(len(rec.matchers))])
        j = judge(rec.est, rec.init, fit, [method_of(m) for m in rec.matchers], cfg)
        back = _restarts(scenario, scans, rec, specs, the_map, cfg, log) if restarts else {}
        mine = verdict_rows(name, rec.matchers, j, cfg, back)
        rows += mine
        beliefs.update({(name, m): j.believed[i] for i, m in enumerate(rec.matchers)})
        tables.append(_scan_table(rec, j, flagged))
        if rec.has_truth.any():
            c = tracker_checks(name, rec.matchers, [r.score_pct for r in mine], j.believed, rec.tracked,
                               rec.has_truth)
            checks += c
            agreements.append(agreement(name, c, rec.tracked, rec.has_truth))
        log(f"{name}: judged {len(rec.matchers)} trackers over {len(scans)} scans ({check.summary()})")
    rows += pooled_rows(rows, beliefs)
    scans_df = pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()
    return Verdict(rows, scans_df, checks, agreements, flags)


def write_verdict(run_dir: str | Path, cfg: TruthFreeConfig = DEFAULT, restarts: bool = True,
                  log: Callable[[str], None] = print) -> Verdict:
    """:func:`judge_run`, then its files and ``run.json``'s ``verdict`` record: the rules, whether
    restarts ran, the hash of the rows judged and the identity of the code that judged them."""
    rd = RunDir(Path(run_dir))
    v = judge_run(run_dir, cfg, restarts, log)
    rd.write(VERDICT, v.rows)
    rd.write(VERDICT_SCANS, v.scans)
    for table, items in ((VERDICT_CHECKS, v.checks), (VERDICT_AGREEMENT, v.agreements), (VERDICT_FLAGS, v.flags)):
        if items:
            rd.write(table, items)
        else:
            rd.remove(table)
    rd.record_verdict(VerdictRecord(asdict(cfg), restarts, rd.rows_sha256(), derived_code(__name__)))
    return v
