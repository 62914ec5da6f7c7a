"""``RUN/timing.md``: the side-by-side timing pass (:mod:`tfloc.harness.timing`; its rows are
``RUN/timing.csv``, written by :mod:`tfloc.harness.timing_pass`) as a table, and the report's line
comparing the run's own CPU times with it."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from tfloc.core.run import TimingRecord
from tfloc.evaluation.contention import MAX_INFLATION, Contention, describe, mark
from tfloc.evaluation.timing import timing_summary
from tfloc.io.atomic import replace_atomically
from tfloc.io.rundir import RunDir
from tfloc.io.tables import TIMING

from .mdtable import num, table


def _load(v: list | None) -> str:
    return num(v[0], 2) if v else "?"


def _commit(git: dict | None) -> str:
    """``abc1234`` (``+ uncommitted changes`` when the tree was dirty), or ``unknown``."""
    c = (git or {}).get("commit")
    if not c:
        return "unknown"
    return f"`{c[:7]}`" + (" with uncommitted changes" if (git or {}).get("dirty") else "")


def _code_line(info: dict) -> str:
    """Which code was timed, against the code that made the run's estimates."""
    if "git" not in info:
        return "- Code timed: not recorded."
    timed, run = _commit(info.get("git")), _commit(info.get("run_git"))
    if timed == run:
        return f"- Code timed: {timed}, the run's own."
    return (f"- Code timed: {timed}; the run's estimates were made by {run} (the timing pass "
            "re-times the matchers as they are now; their answers are not compared here).")


def run_inflation_line(summary: pd.DataFrame, against: str = "this pass") -> str:
    """Whether the run's own CPU times were inflated: the spread of ``run / quiet`` over the
    matchers, said inflated where any is above :data:`~tfloc.evaluation.contention.MAX_INFLATION`
    (empty when the run recorded no CPU times)."""
    r = pd.to_numeric(summary["run_over_quiet"], errors="coerce").dropna()
    if r.empty:
        return ""
    over = summary.loc[r[r > MAX_INFLATION].index, "matcher"].tolist()
    spread = f"×{r.min():.2f}–{r.max():.2f}" if r.min() != r.max() else f"×{r.max():.2f}"
    if not over:
        return f"- The run's own CPU times: not inflated against {against} (run / quiet {spread})."
    return (f"- **The run's own CPU times are inflated** against {against}: run / quiet {spread}, above "
            f"×{MAX_INFLATION:g} for {', '.join(f'`{m}`' for m in over)} (the machine was busier during "
            "the run; read its CPU column through these ratios).")


def run_cpu_note(run_dir: Path, df: pd.DataFrame) -> list[str]:
    """The report's line on the run's own CPU times against its timing pass (``timing.csv``;
    :func:`run_inflation_line`), the pass's contention mark beside it; none without a pass or CPU
    times. ``df``: the run's rows (``cpu_s``, or a prepared table's ``cpu_ms``)."""
    rd = RunDir(run_dir)
    t = rd.frame(TIMING)
    if t.empty:
        return []
    if "cpu_s" not in df and "cpu_ms" in df:
        df = df.assign(cpu_s=df["cpu_ms"] / 1000.0)
    line = run_inflation_line(timing_summary(t, str(t["matcher"].iloc[0]), df),
                              "its timing pass ([timing.md](timing.md), same scans)")
    last = (rd.info().timing or TimingRecord()).last_session
    c = Contention.from_record(last.contention)
    tail = (" The timing pass's own contention was not measured (made before the contention probe)."
            if c is None else f" The timing pass itself ran {mark(c)}." if c.contended else "")
    return [line + tail] if line else []


def contention_line(info: dict) -> str:
    """The pass's contention (:func:`~tfloc.evaluation.contention.describe`), a warning first when
    it ran contended; an older pass's: not measured."""
    c = Contention.from_record(info.get("contention"))
    if c is not None and c.contended:
        return (f"- **This pass ran {mark(c)}**: its milliseconds are not the quiet machine's "
                f"(ratios between matchers hold better). {describe(c)}.")
    return f"- Contention: {describe(c)}."


def timing_markdown(run_name: str, summary: pd.DataFrame, reference: str, info: dict) -> str:
    """The markdown of a timing pass: how it was made, then one row per matcher."""
    has_run = summary["run_cpu_median_ms"].notna().any()
    rows = []
    for r in summary.itertuples():
        cells = [f"`{r.matcher}`", int(r.n),
                 f"{num(r.cpu_median_ms, 2)} [{num(r.cpu_median_lo_ms, 2)}–{num(r.cpu_median_hi_ms, 2)}]",
                 num(r.cpu_p95_ms, 1), num(r.wall_median_ms, 2),
                 f"{num(r.ratio_to_reference, 2)} [{num(r.ratio_lo, 2)}–{num(r.ratio_hi, 2)}]"]
        if has_run:
            cells += [num(r.run_cpu_median_ms, 2), num(r.run_over_quiet, 2)]
        rows.append(cells)
    headers = ["Matcher", "scans", "CPU median (ms) [95 % CI]", "CPU p95 (ms)", "wall median (ms)",
               f"CPU ratio to `{reference}` [95 % CI]"]
    if has_run:
        headers += ["run's CPU median, same scans (ms)", "run / quiet"]
    cores = ", ".join(str(c) for c in info.get("cores", [])) or "not pinned"
    title = f"# Timing pass: {run_name}" + (f" ({m})" if (m := mark(Contention.from_record(
        info.get("contention")))) else "")
    return "\n".join([
        f"{title}\n",
        f"All matchers of the run re-timed side by side on a stratified sample of its scans: "
        f"{info['per_stratum']} scan(s) per dataset × group ({info['strata']} strata, {info['scans']} scans, "
        f"seed {info['seed']}), drawn from the scans every matcher answered in the run. One process pinned to "
        f"core(s) {cores}, every library on one thread; {info['warmup']} untimed warm-up call(s) per dataset "
        f"and matcher; then scan by scan every matcher once, the order rotated by one per scan. Times are "
        f"CPU time of the process during `localize` (wall time beside it). Intervals: bootstrap 95 % "
        f"(medians: resampling times; ratios: resampling scans, paired).\n",
        f"- Started {info.get('started', '?')}; load average (1 min) at the start {_load(info.get('loadavg_start'))}, "
        f"at the end {_load(info.get('loadavg_end'))}.",
        contention_line(info),
        _code_line(info),
        f"- Reference matcher for the ratios: `{reference}`.",
        "- `run / quiet`: the run's own median CPU time on the same scans over this pass's; near 1 "
        "when the run's CPU times can be trusted." if has_run else
        "- The run recorded no CPU times (made before `cpu_s`), so it cannot be compared.",
        *([line] if (line := run_inflation_line(summary)) else []),
        "",
        table(headers, rows)])


def write_timing_md(run_dir: Path, summary: pd.DataFrame, reference: str, info: dict, name: str) -> Path:
    """Write ``timing.md`` atomically (the pass's summary, :func:`timing_markdown`); returns it."""
    rd = RunDir(run_dir)
    text = timing_markdown(name, summary, reference, info)
    replace_atomically(rd.timing_md, lambda fh: fh.write(text))
    return rd.timing_md
