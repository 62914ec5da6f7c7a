"""The report's header: the run's provenance (name, dates, commit, the code that made the rows,
machine, versions against ``requirements.lock``, matchers, datasets, thresholds, rows, load
averages) and the warnings about its times (wall against CPU time, the run's CPU column)."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from tfloc.core.result import kind_of_status
from tfloc.core.run import RunMatcher, RunRecord, Session
from tfloc.core.thresholds import Thresholds
from tfloc.io.lock import LOCK_NAME, find_lock, lock_differences, read_lock

from .mdtable import num
from .timing import run_cpu_note

CONTENTION = 1.5  # median wall / CPU time above this: other processes competed for the cores


def this_run(sessions: tuple[Session, ...]) -> tuple[Session, ...]:
    """The sessions of the run the rows come from: from the last one that started with nothing
    done (``already_done`` 0; an older record's sessions before it ran other rows) to the end."""
    starts = [i for i, x in enumerate(sessions) if not x.already_done]
    return sessions[starts[-1]:] if starts else sessions


def header(run_dir: Path, run: RunRecord, df: pd.DataFrame, thr: Thresholds, s2s: set[str],
           stale_code: list[str] | None = None) -> str:
    """Title and provenance: run, dates, commit, machine, versions, datasets, matchers, thresholds
    (``stale_code``: the labels whose rows this checkout's code would not make; ``None``: not
    checked)."""
    cfg = run.config
    sessions = this_run(run.sessions)
    commit = run.git.commit or "unknown"
    if run.git.dirty:
        commit += " (working tree had uncommitted changes)"
    lines = [f"# tfloc benchmark report: {run.name or run_dir.name}\n",
             f"- Run directory: `{run_dir}`",
             f"- Report generated: {datetime.now(UTC).strftime('%Y-%m-%d %H:%M UTC')}",
             f"- Run started: {sessions[0].started or 'unknown' if sessions else 'unknown'}"
             + (f" ({len(sessions)} sessions, resumed)" if len(sessions) > 1 else ""),
             f"- Commit: `{commit}`",
             code_note(run, stale_code),
             f"- Machine: {run.machine.platform}, {run.machine.cpu_count or '?'} CPUs, Python "
             f"{run.machine.python}; {cfg.jobs if cfg else '?'} worker(s) of one thread each; "
             f"time limit {cfg.timeout_s if cfg else '?'} s per scan",
             "- Versions: " + (", ".join(f"{k} {v}" for k, v in run.versions.items() if v) or "unknown")]
    lines += lock_note(run)
    if not run.exists:
        lines.append("- **run.json is missing**: provenance unknown, default thresholds used.")
    if cfg is not None and cfg.limit_per_group:
        lines.append(f"- **Smoke run**: only the first {cfg.limit_per_group} scans of each group were run.")
    specs = run.matchers or tuple(RunMatcher(m, m, m) for m in sorted(df["matcher"].unique()))
    lines.append("- Matchers: " + ", ".join(
        f"`{m.label}`" + (f" ({m.name} {json.dumps(dict(m.params))})" if m.params or m.name != m.label else "")
        for m in specs))
    lines.append("- Datasets: " + ", ".join(
        f"{d} ({df.loc[df['dataset'] == d, 'scan_id'].nunique()} scans"
        + (", scan-to-scan" if d in s2s else "") + ")" for d in df["dataset"].unique()))
    lines.append(f"- Success thresholds: distance error ≤ {thr.dist_m * 100:g} cm and orientation "
                 f"error ≤ {thr.orient_deg:g}°")
    st = df["status"].map(lambda s: kind_of_status(s) or s)
    lines.append(f"- Rows: {len(df)} (" + ", ".join(f"{k}: {v}" for k, v in st.value_counts().items()) + ")")
    starts = [x.loadavg_start for x in sessions]
    end = sessions[-1].loadavg_end if sessions else None
    if any(starts) or end:
        lines.append("- Load average (1 min) at the start of each session: "
                     + ", ".join(num(v[0], 2) if v else "?" for v in starts)
                     + (f"; at the end: {end[0]:.2f}" if end else "") + f" ({run.machine.cpu_count or '?'} CPUs)")
    lines += contention(df) + run_cpu_note(run_dir, df)
    return "\n".join(lines) + "\n"


def code_note(run: RunRecord, stale: list[str] | None) -> str:
    """The code that made each matcher's rows (its import closure with the row code, recorded
    per matcher in the fingerprint: :mod:`tfloc.harness.identity`) and whether it is this
    checkout's (``stale``: the labels it is not; ``None``: not checked)."""
    recorded = (run.fingerprint or {}).get("matchers") or {}
    if not recorded or not all(isinstance(r, dict) and r.get("source") for r in recorded.values()):
        return "- Code: not recorded per matcher (a run made before per-matcher code identity)"
    if stale is None:
        return "- Code: recorded per matcher (its own code and the harness's row code)"
    return ("- Code: recorded per matcher (its own code and the harness's row code); "
            + (f"all {len(recorded)} are this checkout's" if not stale else
               f"**{len(stale)} of {len(recorded)} not this checkout's** ({', '.join(stale)})"))


def lock_note(run: RunRecord) -> list[str]:
    """Whether the run's recorded package versions are those of the checkout's
    ``requirements.lock`` (nothing when there is no lock or nothing was recorded)."""
    lock, versions = find_lock(), dict(run.versions)
    if lock is None or not versions:
        return []
    diff = lock_differences(versions, read_lock(lock, None if run.machine.python == "?" else run.machine.python))
    if not diff:
        return [f"- Versions: those of `{LOCK_NAME}`"]
    return [f"- **Versions other than `{LOCK_NAME}`'s**: "
            + ", ".join(f"{k} {got or 'not installed'} (lock {want})" for k, (got, want) in sorted(diff.items()))
            + "; answers may differ from a run made with the lock in the last digits, or more"]


def contention(p: pd.DataFrame) -> list[str]:
    """A warning when wall time exceeds CPU time (the machine was shared), or when the run has
    no CPU times (made before ``cpu_s`` was recorded)."""
    if "cpu_ms" not in p or not p["cpu_ms"].notna().any():
        return ["- **No CPU times in this run** (made before `cpu_s` was recorded): the runtime "
                "columns show wall time only, which other processes on the machine inflate."]
    t = p[(p["cpu_ms"] > 0) & p["runtime_ms"].notna()]
    ratio = (t["runtime_ms"] / t["cpu_ms"]).groupby(t["matcher"]).median()
    overall = float((t["runtime_ms"] / t["cpu_ms"]).median())
    if overall <= CONTENTION:
        return [f"- Wall / CPU time per task: median {overall:.2f} (no sign of contention)."]
    return [f"- **Contention**: the median wall / CPU time per task is {overall:.2f} (per matcher: "
            + ", ".join(f"`{m}` {v:.2f}" for m, v in ratio.items()) + f"; > {CONTENTION:g} means other "
            "processes shared the cores). Wall times are inflated, unevenly across matchers; the "
            "runtimes of this report are CPU times, which this affects far less. A quiet side-by-side "
            "re-timing: `tfloc timing RUN` (timing.md)."]
