"""The report's header: the run's provenance (name, dates, commit, the code that made the rows,
machine, versions against ``requirements.lock``, matchers, datasets, thresholds, rows, load
averages) and the warnings about its times (wall against CPU time, the run's CPU column)."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from tfloc.core.thresholds import Thresholds
from tfloc.io.estimates import status_kind
from tfloc.io.lock import LOCK_NAME, find_lock, lock_differences, read_lock

from .mdtable import num
from .sessions import this_run
from .timing import run_cpu_note

CONTENTION = 1.5  # median wall / CPU time above this: other processes competed for the cores


def header(run_dir: Path, run: dict, df: pd.DataFrame, thr: Thresholds, s2s: set[str]) -> str:
    """Title and provenance: run, dates, commit, machine, versions, datasets, matchers, thresholds."""
    cfg = run.get("config", {})
    git = run.get("git", {})
    mach = run.get("machine", {})
    sessions = this_run(run.get("sessions", []))
    commit = git.get("commit") or "unknown"
    if git.get("dirty"):
        commit += " (working tree had uncommitted changes)"
    lines = [f"# tfloc benchmark report: {cfg.get('name', run_dir.name)}\n",
             f"- Run directory: `{run_dir}`",
             f"- Report generated: {datetime.now(UTC).strftime('%Y-%m-%d %H:%M UTC')}",
             f"- Run started: {sessions[0].get('started', 'unknown') if sessions else 'unknown'}"
             + (f" ({len(sessions)} sessions, resumed)" if len(sessions) > 1 else ""),
             f"- Commit: `{commit}`",
             code_note(run),
             f"- Machine: {mach.get('platform', '?')}, {mach.get('cpu_count', '?')} CPUs, Python "
             f"{mach.get('python', '?')}; {cfg.get('jobs', '?')} worker(s) of one thread each; "
             f"time limit {cfg.get('timeout_s', '?')} s per scan",
             "- Versions: " + (", ".join(f"{k} {v}" for k, v in run.get("versions", {}).items() if v) or "unknown")]
    lines += lock_note(run)
    if not run:
        lines.append("- **run.json is missing**: provenance unknown, default thresholds used.")
    lim = cfg.get("limit_per_group")
    if lim:
        lines.append(f"- **Smoke run**: only the first {lim} scans of each group were run.")
    specs = cfg.get("matchers") or [{"label": m, "name": m} for m in sorted(df["matcher"].unique())]
    lines.append("- Matchers: " + ", ".join(
        f"`{m['label']}`" + (f" ({m['name']} {json.dumps(m.get('params', {}))})"
                             if m.get("params") or m["name"] != m["label"] else "") for m in specs))
    lines.append("- Datasets: " + ", ".join(
        f"{d} ({df.loc[df['dataset'] == d, 'scan_id'].nunique()} scans"
        + (", scan-to-scan" if d in s2s else "") + ")" for d in df["dataset"].unique()))
    lines.append(f"- Success thresholds: distance error ≤ {thr.dist_m * 100:g} cm and orientation "
                 f"error ≤ {thr.orient_deg:g}°")
    st = df["status"].map(lambda s: status_kind(s) or s)
    lines.append(f"- Rows: {len(df)} (" + ", ".join(f"{k}: {v}" for k, v in st.value_counts().items()) + ")")
    starts = [x.get("loadavg_start") for x in sessions]
    end = sessions[-1].get("loadavg_end") if sessions else None
    if any(starts) or end:
        lines.append("- Load average (1 min) at the start of each session: "
                     + ", ".join(num(v[0], 2) if v else "?" for v in starts)
                     + (f"; at the end: {end[0]:.2f}" if end else "") + f" ({mach.get('cpu_count', '?')} CPUs)")
    lines += contention(df) + run_cpu_note(run_dir, df)
    return "\n".join(lines) + "\n"


def code_note(run: dict) -> str:
    """The code that made each matcher's rows (its import closure's hash,
    :mod:`tfloc.harness.identity`) and for how many it is this checkout's."""
    from tfloc.core.matcher import factory_of
    from tfloc.errors import TflocError
    from tfloc.harness.identity import matcher_code

    recorded = (run.get("fingerprint") or {}).get("matchers") or {}
    if not recorded or not all(isinstance(r, dict) and r.get("source") for r in recorded.values()):
        return "- Code: not recorded per matcher (a run made before per-matcher code identity)"
    stale = []
    for label, r in recorded.items():
        try:
            now = matcher_code(factory_of(r["name"]))
        except TflocError:
            now = {}
        if now.get("source") != r.get("source"):
            stale.append(label)
    return ("- Code: recorded per matcher (its own code and the harness's row code); "
            + (f"all {len(recorded)} are this checkout's" if not stale else
               f"**{len(stale)} of {len(recorded)} not this checkout's** ({', '.join(stale)})"))


def lock_note(run: dict) -> list[str]:
    """Whether the run's recorded package versions are those of the checkout's
    ``requirements.lock`` (nothing when there is no lock or nothing was recorded)."""
    lock, versions = find_lock(), run.get("versions") or {}
    if lock is None or not versions:
        return []
    diff = lock_differences(versions, read_lock(lock, run.get("machine", {}).get("python")))
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
