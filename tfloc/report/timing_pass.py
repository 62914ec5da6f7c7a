"""The timing pass end to end (``tfloc timing RUN``, a study's ``timing`` step): measure, summarise,
write ``RUN/timing.csv`` and ``RUN/timing.md``, record it in ``RUN/run.json``.

:func:`timing_pass` reads the run, draws the sample, and compares the pass it is asked for with
the one ``run.json`` records (:func:`tfloc.harness.timing.stale`): the same fingerprint, complete,
with its files: nothing is timed ("already complete: timing.md is current"); otherwise, or with
``regenerate``, the run is re-timed (:func:`tfloc.harness.timing.run_timing`), summarised
(:func:`tfloc.evaluation.timing.timing_summary`, from the typed rows' table) and written
(:func:`tfloc.report.timing.write_timing`), the record marked complete only once both files are.
It lives in the report layer because it writes ``timing.md``; the measuring is the harness's.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from tfloc.core.timing_rows import TimingRow
from tfloc.evaluation.timing import timing_summary
from tfloc.harness.runner import load_average
from tfloc.harness.timing import (
    NO_PASS,
    TimingParams,
    read_run,
    run_timing,
    sample_scans,
    stale,
    timing_fingerprint,
)
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import SEQUENCE
from tfloc.io.timing_rows import rows_frame

from .timing import write_timing

Log = Callable[[str], None]


def _stderr(line: str) -> None:
    print(line, file=sys.stderr)


def timing_pass(run_dir: Path, per_stratum: int | None = None, warmup: int | None = None,
                reference: str | None = None, regenerate: bool = False,
                progress: Callable[[int, int], None] | None = None, *, seed: int | None = None,
                cores: Sequence[int] | None = None, log: Log | None = None) -> Path:
    """Re-time the run in ``run_dir`` side by side unless its recorded timing pass is current
    (module notes); returns the run directory.

    ``per_stratum`` scans per dataset × group (default 4), ``warmup`` untimed calls per dataset
    and matcher (default 2), ``reference`` the matcher of the ratios (default tf-plus, else the
    run's first), ``seed`` the sampling seed (default fixed), ``cores`` where to pin (default the
    last allowed core; not part of the pass's fingerprint). ``progress(done, total)`` is told of
    every scan timed; ``log`` (default: standard error) gets why it re-times, the summary table
    and where it wrote. A bad parameter or a run without rows is a :class:`~tfloc.errors.TflocError`."""
    log = log or _stderr
    rd = RunDir(run_dir)
    df, info = read_run(rd.path)
    params = TimingParams.of([m["label"] for m in info.matchers], per_stratum, seed, warmup, reference)
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
    rows, meta = run_timing(rd.path, params.per_stratum, params.seed, cores, params.warmup, progress,
                            run=(df, info), sample=sample)
    summary = timing_summary(rows_frame(rows, TimingRow), params.reference, df)
    csv_path, md_path = write_timing(rd.path, rows, summary, params.reference, meta, info.name or rd.path.name)
    rd.close_timing(load_average(), cores=meta["cores"], scans=meta["scans"])
    log(summary[["matcher", "cpu_median_ms", "ratio_to_reference", "run_over_quiet"]].to_string(
        index=False, float_format=lambda v: f"{v:.2f}"))
    log(f"timing: {md_path} ({csv_path.name})")
    return rd.path
