"""Check a committed timing pass (``tfloc timing RUN --verify``): re-time its sample now and compare.

The scans of ``RUN/timing.csv`` (the first ``per_stratum`` of each dataset × group when asked
for fewer; a sequence's first steps) are timed again as the pass timed them
(:func:`tfloc.harness.timing.run_timing`, the record's warm-up), contended tries retried or refused
as a pass's are (:func:`tfloc.report.timing_pass.timed_quietly`), nothing written. Per matcher the
median CPU ms over the same scans, committed and now, and the ratio
(:func:`tfloc.evaluation.timing.verify_ratios`); the check fails where a ratio lies outside
×1/``tolerance``–×``tolerance`` (default ×1.3: a pass's figures are the quiet machine's within that).

The probe judges each pass against itself (its calibration's median over its minimum), so a
machine slowed throughout a pass reads quiet. Two passes are compared only when the machine ran
the calibration at the same speed in both: its best round now over its best round then
(:func:`machine_ratio`) within the probe's own limit (×1/1.25–×1.25, :data:`MAX_INFLATION`); a
re-timing outside it is retried and refused as a contended one is (with ``allow_contended``,
compared and said so). The table's ``per_machine`` column is each ratio over that machine ratio.

Absolute CPU times compare only on one CPU model. The committed pass's model is its session's
``cpu`` in the timing record, else (a record made before the pass recorded it) the run's
``machine.cpu`` (:func:`committed_cpu`, which says which it read). When it is another model than
this machine's (:func:`other_cpu`, one line saying so) the check compares the matchers' ratios to
one another instead, measured side by side: per matcher its median over the reference matcher's
(the record's ``reference``), committed and now, and the one now over the one committed
(:func:`tfloc.evaluation.timing.between_ratios`), each within ×1/``tolerance``–×``tolerance``.
The machine ratio is then no reason to retry or refuse (its calibration measures another
processor); contention within the re-timing, by its own probe, still is.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path

import pandas as pd

from tfloc.core.rows.timing import TimingRow
from tfloc.core.run import RunRecord, TimingRecord
from tfloc.errors import ConfigError
from tfloc.evaluation.contention import MAX_INFLATION, Contention, describe
from tfloc.evaluation.timing import between_ratios, outside, reference_of, verify_ratios, within
from tfloc.harness.runner import cpu_model
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import SEQUENCE
from tfloc.io.table import frame_of
from tfloc.io.tables import TIMING

from .timing import WARMUP, read_run, run_timing
from .timing_pass import RETRIES, WAIT_S, Log, _stderr, timed_quietly

TOLERANCE = 1.3


def committed_sample(committed: pd.DataFrame, sequences: Sequence[str], per_stratum: int | None) -> pd.DataFrame:
    """The scans of a committed pass (dataset, scan_id, group in their order), or the first
    ``per_stratum`` of each dataset × group (of a sequence, its first ``per_stratum`` steps)."""
    s = committed[["dataset", "scan_id", "group"]].drop_duplicates(["dataset", "scan_id"]).reset_index(drop=True)
    if per_stratum is None:
        return s
    if per_stratum < 1:
        raise ConfigError(f"per-stratum sample size must be ≥ 1, got {per_stratum}")
    seq = s["dataset"].isin(set(sequences))
    return pd.concat([s[~seq].groupby(["dataset", "group"], sort=False).head(per_stratum),
                      s[seq].groupby("dataset", sort=False).head(per_stratum)]).sort_index()


def machine_ratio(then: Contention | None, now: Contention | None) -> float:
    """The calibration's fastest round now over its fastest round in the committed pass (NaN where
    either pass was not measured): how much slower the machine itself runs the same work now."""
    if then is None or now is None or not then.calib_min_ms > 0 or not now.calib_min_ms > 0:
        return math.nan
    return now.calib_min_ms / then.calib_min_ms


def apart_from(then: Contention | None, limit: float = MAX_INFLATION) -> Callable[[Contention], str | None]:
    """For :func:`~tfloc.report.timing_pass.timed_quietly`: why a re-timing cannot be compared
    with the committed pass ``then`` (the machine ratio outside ×1/``limit``–×``limit``), or None."""
    def apart(now: Contention) -> str | None:
        m = machine_ratio(then, now)
        if math.isnan(m) or within(m, limit):
            return None
        return (f"the calibration's best round is ×{m:.2f} the committed pass's "
                f"({now.calib_min_ms:.2f} ms against {then.calib_min_ms:.2f}; limit ×{limit:g})")
    return apart


def committed_cpu(info: RunRecord) -> tuple[str | None, str]:
    """The CPU model the committed pass of the run ``info`` was timed on and where it was read:
    the pass's last session (``timing``'s ``cpu``), else the run's machine (``machine.cpu``: a
    pass recorded before it named its CPU), else ``(None, "not recorded")``."""
    cpu = (info.timing or TimingRecord()).last_session.cpu
    if isinstance(cpu, str) and cpu.strip():
        return cpu.strip(), "the timing pass's record"
    cpu = info.machine.cpu if info.machine.cpu != "?" else None
    if isinstance(cpu, str) and cpu.strip():
        return cpu.strip(), "the run's machine.cpu: the timing record names none"
    return None, "not recorded"


def other_cpu(then: str | None, now: str | None) -> str | None:
    """The one line saying the committed pass was timed on another CPU model (``then``) than this
    one (``now``), or None: the same model (names compared with their spaces folded), or either
    unknown (then compared as one model)."""
    if not then or not now or " ".join(then.split()) == " ".join(now.split()):
        return None
    return (f"timed on {then}, this is {now}: absolute CPU times are not comparable; "
            "comparing the matchers' ratios to one another, measured side by side")


def _models(info: RunRecord, here: str, log: Log) -> str | None:
    """Log the committed pass's CPU model (and where it was read) and this machine's ``here``,
    then, on another model, the line saying so (:func:`other_cpu`); returns that line or None."""
    model, source = committed_cpu(info)
    log(f"CPU model: committed pass {model or 'unknown'} ({source}), this machine {here or 'unknown'}")
    other = other_cpu(model, here)
    if other:
        log(other)
    return other


def verify_pass(run_dir: Path, per_stratum: int | None = None, cores: Sequence[int] | None = None,
                log: Log | None = None, tolerance: float = TOLERANCE, allow_contended: bool = False,
                retries: int = RETRIES, wait_s: float = WAIT_S,
                progress: Callable[[int, int], None] | None = None, cpu: str | None = None) -> bool:
    """Re-time the committed pass of ``run_dir`` and log the comparison (module notes); True when
    every matcher's ratio lies within ``tolerance`` (on another CPU model: its ratio to the
    reference now over committed). ``cpu``: this machine's CPU model (default
    :func:`~tfloc.harness.runner.cpu_model`). A run without ``timing.csv`` is a
    :class:`~tfloc.errors.ConfigError`."""
    log = log or _stderr
    rd = RunDir(run_dir)
    df, info = read_run(rd.path)
    committed = rd.frame(TIMING)
    if committed.empty:
        raise ConfigError(f"{rd.path}: no timing pass to verify (no timing.csv; tfloc timing {rd.path} makes one)")
    record = info.timing or TimingRecord()
    fp = record.fingerprint or {}
    then = Contention.from_record(record.last_session.contention)
    sequences = sorted(info.datasets_in(list(df["dataset"].unique()), SEQUENCE))
    sample = committed_sample(committed, sequences, per_stratum)
    warmup = int(fp.get("warmup", WARMUP))
    try:
        reference = reference_of(list(dict.fromkeys(committed["matcher"])), fp.get("reference") or None)
    except ValueError as exc:
        raise ConfigError(f"{rd.path}: {exc}") from None
    other = _models(info, cpu if cpu is not None else cpu_model(), log)
    rows, meta = timed_quietly(lambda: run_timing(rd.path, cores=cores, warmup=warmup, progress=progress,
                                                  run=(df, info), sample=sample),
                               log, allow_contended, retries, wait_s, f"{rd.path} (verify)",
                               apart=None if other else apart_from(then))
    table = verify_ratios(committed, frame_of(rows, TimingRow))
    try:
        between = between_ratios(table, reference)
    except ValueError as exc:
        raise ConfigError(f"{rd.path}: {exc}") from None
    now = Contention.from_record(meta["contention"])
    log(f"committed pass: {describe(then)}")
    log(f"this re-timing ({len(sample)} scans): {describe(now)}")
    if other:
        log(side_by_side(between, reference))
        return _verdict(rd.path, between, tolerance, log, reference)
    machine = machine_ratio(then, now)
    table["per_machine"] = table["ratio"] / machine
    if not math.isnan(machine):
        log(f"machine now / then: ×{machine:.2f} (the calibration's best round); per_machine = ratio over it")
    log(table.to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    log(f"each matcher's ratio to {reference}, committed and now (not judged on the same CPU model):\n"
        f"{side_by_side(between, reference)}")
    return _verdict(rd.path, table, tolerance, log)


def side_by_side(between: pd.DataFrame, reference: str) -> str:
    """:func:`~tfloc.evaluation.timing.between_ratios`' table as text: per matcher its median CPU
    over ``reference``'s, committed and now, and the one now over the one committed."""
    names = {"committed_to_ref": f"committed/{reference}", "now_to_ref": f"now/{reference}",
             "ratio": "now/committed"}
    return between.rename(columns=names).to_string(index=False, float_format=lambda v: f"{v:.2f}")


def _verdict(path: Path, table: pd.DataFrame, tolerance: float, log: Log, reference: str | None = None) -> bool:
    """Log whether every ``ratio`` of ``table`` lies within ×1/``tolerance``–×``tolerance`` and
    return it; ``reference``: the ratios are the matchers' to it (another CPU model)."""
    bad = outside(table, tolerance)
    if bad:
        to = f" in the matchers' ratios to {reference}" if reference else ""
        log(f"{path}: the committed timing pass does NOT agree within ×{tolerance:g}{to}: {', '.join(bad)}")
        return False
    every = f"every matcher's ratio to {reference}" if reference else "every matcher"
    log(f"{path}: the committed timing pass agrees within ×{tolerance:g} for {every} "
        f"(ratios {table['ratio'].min():.2f}–{table['ratio'].max():.2f})")
    return True
