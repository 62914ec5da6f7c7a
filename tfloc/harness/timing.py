"""A side-by-side timing pass: the run's matchers re-timed on a sample of its scans, in one process.

The benchmark's own runtimes come from two workers on a machine other jobs may share; their CPU
time is robust to that, their wall time is not, and neither is measured side by side. This pass
re-times a stratified sample of a run's scans so that the matchers are compared under the same
conditions:

* **Sample**: per stratum (dataset × group, e.g. one offset cell) ``per_stratum`` scans drawn
  with a seeded generator from the scans every matcher of the run answered (a scan on which a
  matcher timed out or raised in the run is left out: it would dominate the pass's time); of a
  sequence, its first ``per_stratum`` × 100 scans, every tracker stepping along them in turn.
* **One process pinned to the configured cores**, every library on one thread, the matchers
  interleaved scan by scan in rotated order (:mod:`tfloc.harness.pinning`).
* **Warm-up**: for each dataset and matcher, :func:`tfloc.harness.workspace.warm` and ``warmup``
  untimed ``localize`` calls on sampled scans (kernels, map-only structures, the allocator).
* Each call is timed by CPU time (``time.process_time``) and wall time (``time.perf_counter``).
* **Contention probe** (:mod:`tfloc.harness.contention`): a fixed calibration workload timed at
  the start and before each scan's (or step's) matchers, and the machine's busy time over the
  pass; :mod:`tfloc.evaluation.contention` says whether the pass ran contended.

:func:`run_timing` returns one :class:`~tfloc.core.rows.timing.TimingRow` per (scan, matcher).
A pass is one configuration (:func:`timing_fingerprint`: the run's fingerprint, the pass's
:class:`TimingParams`, the sample drawn and the code timed), recorded in the run's ``run.json``
(:meth:`~tfloc.io.rundir.RunDir.start_timing`); :func:`stale` says why a recorded pass is not
current. :func:`tfloc.harness.timing_pass.timing_pass` runs it end to end (``tfloc timing``):
``RUN/timing.csv``, ``RUN/timing.md``. A pass is short and runs whole: an interrupted one is
timed again from the start, never resumed.
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from tfloc.core.jsonable import jsonable
from tfloc.core.matcher import get_matcher
from tfloc.core.rows.timing import TimingRow
from tfloc.core.run import RunMatcher, RunRecord, TimingRecord
from tfloc.errors import ConfigError
from tfloc.evaluation.timing import reference_of
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import SEQUENCE, load_dataset
from tfloc.io.tables import TIMING

from .contention import Probe
from .fingerprint import differences
from .identity import derived_code, git_state
from .pinning import pinned, rotated
from .runner import cpu_model, load_average
from .workspace import load_matcher, map_of, problem_of, timed_localize, warm

SEED = 20261130
PER_STRATUM = 4  # scans per dataset × group, by default
STEPS = 100      # a sequence's first steps timed per unit of ``per_stratum``
WARMUP = 2       # untimed localize calls per dataset and matcher, by default
NO_PASS = "no timing pass yet"


@dataclass(frozen=True)
class TimingParams:
    """What a timing pass is asked for: scans per stratum, the sampling seed, untimed warm-up
    calls per dataset and matcher, and the reference matcher of the ratios (a label)."""

    per_stratum: int = PER_STRATUM
    seed: int = SEED
    warmup: int = WARMUP
    reference: str = ""

    @classmethod
    def of(cls, labels: Sequence[str], per_stratum: int | None = None, seed: int | None = None,
           warmup: int | None = None, reference: str | None = None) -> TimingParams:
        """The parameters for a run of matchers ``labels``, a default for every ``None`` (the
        reference: tf-plus if the run has it, else its first matcher); a bad one is a
        :class:`ConfigError`."""
        try:
            ref = reference_of(list(labels), reference)
        except (ValueError, IndexError) as exc:
            raise ConfigError(str(exc) or "the run has no matcher") from None
        p = cls(PER_STRATUM if per_stratum is None else per_stratum, SEED if seed is None else seed,
                WARMUP if warmup is None else warmup, ref)
        if p.per_stratum < 1 or p.warmup < 0:
            raise ConfigError(f"per-stratum sample size must be ≥ 1 and warm-up ≥ 0, got {p.per_stratum} "
                              f"and {p.warmup}")
        return p


def read_run(run_dir: Path) -> tuple[pd.DataFrame, RunRecord]:
    """The rows and ``run.json`` of a run (:class:`~tfloc.io.rundir.RunDir`; both required)."""
    rd = RunDir(run_dir)
    info = rd.info(required=True)
    return rd.results(), info


def sample_scans(df: pd.DataFrame, per_stratum: int, seed: int = SEED,
                 sequences: Sequence[str] = ()) -> pd.DataFrame:
    """``per_stratum`` scans per (dataset, group) that every matcher answered, seeded; of a
    sequence dataset (``sequences``), its first ``per_stratum`` × :data:`STEPS` scans in order
    (a tracker's step depends on the steps before it). Columns dataset, scan_id, group, in
    dataset order, then group, then scan id (a sequence's in its own order)."""
    if per_stratum < 1:
        raise ConfigError(f"per-stratum sample size must be ≥ 1, got {per_stratum}")
    seq = df[df["dataset"].isin(set(sequences))]
    heads = [g[["dataset", "scan_id", "group"]].drop_duplicates("scan_id").head(per_stratum * STEPS)
             for _, g in seq.groupby("dataset", sort=False)]
    df = df[~df["dataset"].isin(set(sequences))]
    if df.empty:
        return (pd.concat(heads, ignore_index=True) if heads
                else pd.DataFrame(columns=["dataset", "scan_id", "group"]))
    answered = df["status"].fillna("").isin(["ok", "failed"])
    n_matchers = df["matcher"].nunique()
    ok = df[answered].groupby(["dataset", "scan_id"])["matcher"].nunique() == n_matchers
    good = set(ok[ok].index)
    scans = df[["dataset", "scan_id", "group"]].drop_duplicates(["dataset", "scan_id"])
    scans = scans[[k in good for k in zip(scans["dataset"], scans["scan_id"], strict=True)]]
    rng = np.random.default_rng(seed)
    parts = []
    order = {d: i for i, d in enumerate(dict.fromkeys(df["dataset"]))}
    for _, g in sorted(scans.groupby(["dataset", "group"], sort=True), key=lambda kv: (order[kv[0][0]], kv[0][1])):
        g = g.sort_values("scan_id")
        parts.append(g.iloc[np.sort(rng.choice(len(g), size=min(per_stratum, len(g)), replace=False))])
    cols = ["dataset", "scan_id", "group"]
    parts += heads
    return pd.concat(parts, ignore_index=True)[cols] if parts else pd.DataFrame(columns=cols)


def timing_fingerprint(run_fingerprint: dict | None, params: TimingParams, sample: pd.DataFrame) -> dict:
    """What decides a timing pass's rows: the run's fingerprint, the pass's parameters, the
    sampled scans (SHA-256 of their keys: the run's rows decide the sample) and the code that
    times (this module's import closure: the matchers' own code is in the run's fingerprint);
    JSON-normalised."""
    keys = "\n".join(f"{d}\t{s}" for d, s in zip(sample["dataset"], sample["scan_id"], strict=True))
    fp = {"run": run_fingerprint, "tfloc": {"source": derived_code(__name__)}, **asdict(params),
          "sample": hashlib.sha256(keys.encode()).hexdigest()}
    return jsonable(fp)


def stale(rd: RunDir, record: TimingRecord | None, fp: dict) -> list[str]:
    """Why the run's recorded timing pass (``record``: ``run.json``'s ``timing``) is not the one
    of ``fp``, one phrase each; empty when it is complete, its files are there and it is current.
    With no record and no ``timing.md``, ``[NO_PASS]``."""
    if record is None:
        return ["timing.md records no fingerprint (made by an older tfloc)" if rd.timing_md.exists() else NO_PASS]
    old = dict(record.fingerprint or {})
    out = [] if record.complete else ["the last timing pass did not finish"]
    out += [f"{f.name}: none" for f in (rd.file(TIMING), rd.timing_md) if not f.exists()]
    params = [f"{k} {json.dumps(old.get(k))} → {json.dumps(fp[k])}" for k in asdict(TimingParams()) if old.get(k) != fp[k]]
    out += params
    if old.get("run") != fp["run"]:
        why = differences(old.get("run"), fp["run"]) if isinstance(fp["run"], dict) else []
        out.append("the run changed" + (f" ({why[0]})" if why else ""))
    if (old.get("tfloc") or {}).get("source") != fp["tfloc"]["source"]:
        out.append(f"the timing code changed (source {str((old.get('tfloc') or {}).get('source'))[:12]} → "
                   f"{fp['tfloc']['source'][:12]})")
    if old.get("sample") != fp["sample"] and old.get("run") == fp["run"] and not params:
        out.append("the run's rows changed (another sample of scans)")
    return out


def run_timing(run_dir: Path, per_stratum: int = PER_STRATUM, seed: int = SEED, cores: Sequence[int] | None = None,
               warmup: int = WARMUP, progress: Callable[[int, int], None] | None = None,
               run: tuple[pd.DataFrame, RunRecord] | None = None,
               sample: pd.DataFrame | None = None) -> tuple[list[TimingRow], dict]:
    """Re-time a stratified sample of the run in ``run_dir`` (see the module docstring), pinned
    to ``cores`` (default: the last core this process may run on).

    Returns the rows (times in ms) and a provenance dict (cores, ``cpu``: the CPU's model name
    (:func:`~tfloc.harness.runner.cpu_model`), load averages, sample size, seed, ``contention``:
    the probe's figures as :meth:`~tfloc.evaluation.contention.Contention.to_record` gives them). ``run``: the run's rows
    and ``run.json`` if the caller has already read them
    (:func:`read_run`); ``sample``: the scans if it has drawn them (:func:`sample_scans`)."""
    df, info_run = read_run(run_dir) if run is None else run
    specs = [m for m in info_run.matchers if m.label in set(df["matcher"])]
    paths = info_run.paths
    sequences = sorted(info_run.datasets_in(list(df["dataset"].unique()), SEQUENCE))
    sample = sample_scans(df, per_stratum, seed, sequences) if sample is None else sample
    if sample.empty:
        raise ConfigError(f"{run_dir}: no scan that every matcher answered")
    started, load_start = time.strftime("%Y-%m-%dT%H:%M:%S%z"), load_average()
    probe = Probe()
    with pinned(cores) as on:
        single = sample[~sample["dataset"].isin(sequences)]
        steps = sample[sample["dataset"].isin(sequences)]
        probe.start()
        rows = _time_sample(single, specs, paths, warmup, progress, probe) if len(single) else []
        rows += _time_sequences(steps, specs, paths, progress, len(single), probe)
        contention = probe.finish()
    info = {"cores": on, "cpu": cpu_model(), "per_stratum": per_stratum, "seed": seed, "warmup": warmup,
            "contention": contention.to_record(),
            "scans": len(sample), "strata": int(sample.groupby(["dataset", "group"]).ngroups),
            "loadavg_start": load_start, "loadavg_end": load_average(), "started": started,
            "git": git_state(), "run_git": info_run.git.to_dict()}
    return rows, info


def _time_sample(sample: pd.DataFrame, specs: list[RunMatcher], paths: dict[str, Path], warmup: int,
                 progress: Callable[[int, int], None] | None, probe: Probe | None = None) -> list[TimingRow]:
    """Warm up, then time every matcher on every sampled scan, interleaved (module docstring),
    the calibration workload before each scan's matchers (``probe``)."""
    matchers = [(m.label, load_matcher(m.name, m.params_json)) for m in specs]
    problems = {}
    for d, g in sample.groupby("dataset", sort=False):
        if d not in paths:
            raise ConfigError(f"dataset {d!r} has no directory in run.json")
        scenario, scans = load_dataset(str(paths[d]))
        problems[d] = (scenario, scans)
        first = [scans[s] for s in g["scan_id"].iloc[:max(1, warmup)]]
        for _, m in matchers:  # untimed: kernels, map-only structures, allocator
            warm(m, problem_of(scenario, first[0]))
            for scan in first[:warmup]:
                m.localize(problem_of(scenario, scan))
    rows = []
    for i, r in enumerate(sample.itertuples(index=False)):
        scenario, scans = problems[r.dataset]
        scan = scans[r.scan_id]
        if probe is not None:
            probe.round()
        for pos, (label, m) in rotated(matchers, i):
            t = timed_localize(m, problem_of(scenario, scan))
            rows.append(TimingRow(str(r.dataset), str(r.scan_id), str(r.group), label, pos,
                                  1000.0 * t.cpu_s, 1000.0 * t.wall_s))
        if progress:
            progress(i + 1, len(sample))
    return rows


def _time_sequences(sample: pd.DataFrame, specs: list[RunMatcher], paths: dict[str, Path],
                    progress: Callable[[int, int], None] | None, done: int = 0,
                    probe: Probe | None = None) -> list[TimingRow]:
    """Every tracker of the run along the sampled first steps of each sequence, started and
    warmed up (untimed) as the tracking loop does, their steps interleaved in rotated order
    (:func:`tfloc.harness.track.step`: the tracking loop's own step, each tracker on its own
    answers). A tracker that answers whole sequences at once (an external program) has no step
    to time here: it is left out (its rows carry its child process's CPU time)."""
    from tfloc.core.external import is_batch_tracker
    from tfloc.core.tracker import as_tracker

    from .track import begin, odom_deltas, step

    rows: list[TimingRow] = []
    total = done + len(sample)
    for d, g in sample.groupby("dataset", sort=False):
        scenario, by_id = load_dataset(str(paths[d]))
        scans = list(by_id.values())[:len(g)]
        the_map = map_of(scenario, scans[0])
        trackers = [(m.label, as_tracker(get_matcher(m.name, **m.params))) for m in specs]
        trackers = [(label, t) for label, t in trackers if not is_batch_tracker(t)]
        for _, t in trackers:
            begin(t, scenario, scans, the_map)
        for k, (scan, delta) in enumerate(zip(scans, odom_deltas(scans), strict=True)):
            if probe is not None:
                probe.round()
            for pos, (label, t) in rotated(trackers, k):
                s = step(t, scenario, scan, delta)
                if s.cpu_s is not None:
                    rows.append(TimingRow(str(d), str(scan.scan_id), str(scan.group), label, pos,
                                          1000.0 * s.cpu_s, 1000.0 * s.wall_s))
            done += 1
            if progress:
                progress(done, total)
    return rows
