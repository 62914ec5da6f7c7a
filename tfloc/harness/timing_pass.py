"""The timing pass end to end (``tfloc timing RUN``, a study's ``timing`` step): measure, summarise,
write ``RUN/timing.csv`` and ``RUN/timing.md``, record it in ``RUN/run.json``.

:func:`timing_pass` reads the run, draws the sample, and compares the pass it is asked for with
the one ``run.json`` records (:func:`tfloc.harness.timing.stale`): the same fingerprint, complete,
with its files: nothing is timed ("already complete: timing.md is current"); otherwise, or with
``regenerate``, the run is re-timed (:func:`tfloc.harness.timing.run_timing`), summarised
(:func:`tfloc.evaluation.timing.timing_summary`, from the typed rows' table) and written: the
rows through the store, ``timing.md`` by the ``draw`` the caller passes
(:func:`tfloc.report.timing.write_timing_md`, from the command line), the record marked complete
only once both files are; its session records the cores and the CPU model it ran on (``cpu``:
absolute CPU times compare only on one model, :mod:`tfloc.harness.timing_verify`) and the
probe's ``contention``.

A pass the contention probe finds contended (:mod:`tfloc.evaluation.contention`) is timed again
after ``wait_s`` seconds, up to ``retries`` times, then refused with a one-line
:class:`ContendedError` (nothing written, the record left incomplete); with ``allow_contended``
it is written at once, marked contended in ``timing.md`` and ``run.json``.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import pandas as pd

from tfloc.core.rows.timing import TimingRow
from tfloc.errors import TflocError
from tfloc.evaluation.contention import Contention, describe
from tfloc.evaluation.timing import timing_summary
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import SEQUENCE
from tfloc.io.table import frame_of
from tfloc.io.tables import TIMING

from .runner import load_average
from .timing import (
    NO_PASS,
    TimingParams,
    read_run,
    run_timing,
    sample_scans,
    stale,
    timing_fingerprint,
)

Log = Callable[[str], None]
#: writes ``timing.md``: (run directory, summary, reference, the pass's provenance, run name) → its path
Draw = Callable[[Path, pd.DataFrame, str, dict, str], Path]
RETRIES = 2    # a contended pass is timed again this many times before it is refused
WAIT_S = 60.0  # seconds between those tries


class ContendedError(TflocError):
    """A timing pass ran contended every time it was tried (and contended passes are not allowed)."""


def _stderr(line: str) -> None:
    print(line, file=sys.stderr)


def timing_pass(run_dir: Path, per_stratum: int | None = None, warmup: int | None = None,
                reference: str | None = None, regenerate: bool = False,
                progress: Callable[[int, int], None] | None = None, *, seed: int | None = None,
                cores: Sequence[int] | None = None, log: Log | None = None, allow_contended: bool = False,
                retries: int = RETRIES, wait_s: float = WAIT_S, draw: Draw | None = None) -> Path:
    """Re-time the run in ``run_dir`` side by side unless its recorded timing pass is current
    (module notes); returns the run directory.

    ``per_stratum`` scans per dataset × group (default 4), ``warmup`` untimed calls per dataset
    and matcher (default 2), ``reference`` the matcher of the ratios (default tf-plus, else the
    run's first), ``seed`` the sampling seed (default fixed), ``cores`` where to pin (default the
    last allowed core; not part of the pass's fingerprint). ``progress(done, total)`` is told of
    every scan timed; ``log`` (default: standard error) gets why it re-times, the summary table
    and where it wrote; ``draw`` writes ``timing.md`` (none: the pass is left without it, so not
    complete). A bad parameter or a run without rows is a :class:`~tfloc.errors.TflocError`;
    contended passes are retried or refused as the module notes say."""
    log = log or _stderr
    rd = RunDir(run_dir)
    df, info = read_run(rd.path)
    params = TimingParams.of(info.labels, per_stratum, seed, warmup, reference)
    sequences = sorted(info.datasets_in(list(df["dataset"].unique()), SEQUENCE))
    sample = sample_scans(df, params.per_stratum, params.seed, sequences)
    fp = timing_fingerprint(info.fingerprint, params, sample)
    why = stale(rd, info.timing, fp)
    if not why and not regenerate:
        log(f"{rd.path}: already complete: timing.md is current (--regenerate times it again)")
        return rd.path
    if why and why != [NO_PASS]:
        log(f"{rd.path}: timing again: {'; '.join(why[:3])}" + (f" (and {len(why) - 3} more)" if len(why) > 3 else ""))
    elif not why:
        log(f"{rd.path}: timing again (--regenerate)")
    rd.start_timing(fp, load_average(), fresh=regenerate or bool(why))
    rows, meta = timed_quietly(lambda: run_timing(rd.path, params.per_stratum, params.seed, cores, params.warmup,
                                                  progress, run=(df, info), sample=sample),
                               log, allow_contended, retries, wait_s, str(rd.path))
    summary = timing_summary(frame_of(rows, TimingRow), params.reference, df)
    csv_path = rd.write(TIMING, rows)
    if draw is None:
        log(f"timing: {csv_path} (no timing.md drawn: the pass is not complete)")
        return rd.path
    md_path = draw(rd.path, summary, params.reference, meta, info.name or rd.path.name)
    rd.close_timing(load_average(), cores=meta["cores"], cpu=meta["cpu"], scans=meta["scans"],
                    contention=meta["contention"])
    log(summary[["matcher", "cpu_median_ms", "ratio_to_reference", "run_over_quiet"]].to_string(
        index=False, float_format=lambda v: f"{v:.2f}"))
    log(f"timing: {md_path} ({csv_path.name})")
    return rd.path


def timed_quietly(timed: Callable[[], tuple[list, dict]], log: Log, allow_contended: bool = False,
                  retries: int = RETRIES, wait_s: float = WAIT_S, what: str = "timing pass",
                  apart: Callable[[Contention], str | None] | None = None) -> tuple[list, dict]:
    """``timed()`` (rows and a provenance dict with ``contention``) until its probe finds it
    quiet: a contended try is timed again after ``wait_s`` s, at most ``retries`` times, then
    refused (:class:`ContendedError`); with ``allow_contended`` the first try is kept, contended
    or not (module notes). ``apart``, when given, names a further reason a try's figures cannot
    be used (None: they can), treated as contention (``--verify``: the machine itself runs at
    another speed than when the pass it checks was made)."""
    why: list[str] = []
    for attempt in range(retries + 1):
        rows, meta = timed()
        c = Contention.from_record(meta.get("contention"))
        far = apart(c) if apart is not None and c is not None else None
        why = (c.reasons() if c is not None else []) + ([far] if far else [])
        if not why:
            return rows, meta
        log(f"{what}: {describe(c)}" + (f"; {far}" if far else ""))
        if allow_contended:
            log(f"{what}: kept as contended (--allow-contended)")
            return rows, meta
        if attempt < retries:
            log(f"{what}: timing again in {wait_s:g} s (try {attempt + 2} of {retries + 1})")
            time.sleep(wait_s)
    raise ContendedError(f"{what}: contended on each of {retries + 1} tries ({'; '.join(why)}); "
                         "run it on a quiet machine, or pass --allow-contended to keep it marked contended")
