"""The headline section that opens every ``report.md``: one ranked table per mode of the run,
pooled over its datasets of that mode (or its one dataset), from the rows of ``headline.csv``
(computed once by :func:`tfloc.evaluation.headline.headline` in the derive step). The README and
the site print the same rows."""

from __future__ import annotations

import math

from tfloc.core.modes import MODES, SEQUENCE, mode_of
from tfloc.core.modes import TRUTH_FREE as FREE_MODE
from tfloc.core.rows.headline import POOLED, HeadlineRow
from tfloc.core.thresholds import Thresholds

from .mdtable import num, table

TRUTH_FREE = FREE_MODE.key


def interval(r: HeadlineRow) -> str:
    """``value [lo–hi]`` in percent (the interval left out where there is none)."""
    ci = "" if math.isnan(r.lo_pct) else f" [{r.lo_pct:.1f}–{r.hi_pct:.1f}]"
    return f"{r.value_pct:.1f}{ci}"


def verdict(r: HeadlineRow) -> str:
    """The paired test against the next matcher down, in words."""
    if not r.verdict:
        return "—"
    return f"{r.verdict} of `{r.next_matcher}` (p = {r.p_holm:.2g})" if r.verdict == "ahead" else \
        f"tied with `{r.next_matcher}` (p = {r.p_holm:.2g})"


def headline_table(rows: list[HeadlineRow]) -> str:
    """The markdown table of one headline (rows of one mode and scope, in rank order)."""
    if not rows:
        return ""
    first = rows[0]
    unit = "CPU ms/step" if first.mode == SEQUENCE.key else "CPU ms/scan"
    if first.measure == TRUTH_FREE:  # no truth: no error column, no truth-based figure
        body = [[r.rank, f"`{r.matcher}`", interval(r), num(r.cpu_ms, 2), r.n, verdict(r)] for r in rows]
        return table(["#", "tracker", "believed tracked % [95 % CI]", f"{unit} (median)", "scans",
                      "against the next"], body, "rlrrrl")
    body = [[r.rank, f"`{r.matcher}`", interval(r), num(r.error_cm, 2), num(r.cpu_ms, 2), r.n, verdict(r)]
            for r in rows]
    return table(["#", "matcher", f"{first.measure} % [95 % CI]", f"{first.error} (cm)",
                  f"{unit} (median)", "scans", "against the next"], body, "rlrrrrl")


def top_scope(rows: list[HeadlineRow], mode: str, measure: str | None = None) -> str:
    """The scope a report shows for ``mode`` (and ``measure``): the pooled table, else its first
    dataset."""
    scopes = [r.scope for r in rows if r.mode == mode and measure in (None, r.measure)]
    return POOLED if POOLED in scopes else scopes[0]


def _table_key(r: HeadlineRow) -> str:
    return TRUTH_FREE if r.measure == TRUTH_FREE else r.mode


def headline_section(rows: list[HeadlineRow], thr: Thresholds, note: str = "") -> str:
    """The report's opening section from the run's headline rows (every table: each dataset, and
    each mode pooled); datasets without truth are ranked by the truth-free verdict, and that
    ranking comes first (``note``: why there is no current verdict, if so)."""
    if not rows:
        why = f" ({note})" if note else ""
        return f"## Headline\n\n_No scan of this run has ground truth: nothing to rank{why}._\n"
    out = ["## Headline\n"]
    keys = sorted(dict.fromkeys(_table_key(r) for r in rows), key=lambda k: k != TRUTH_FREE)
    for key in keys:
        measure = TRUTH_FREE if key == TRUTH_FREE else None
        mode = SEQUENCE.key if key == TRUTH_FREE else key
        mine_all = [r for r in rows if _table_key(r) == key]
        scope = top_scope(mine_all, mode, measure)
        mine = [r for r in mine_all if r.scope == scope]
        names = sorted({r.scope for r in mine_all if r.scope != POOLED}) or [scope]
        where = f"pooled over {', '.join(names)}" if scope == POOLED else scope
        rule = "share of scans believed tracked, judged without the truth (docs/truth-free.md)" \
            if key == TRUTH_FREE else f"{mine[0].measure}: within {thr.dist_m * 100:g} cm and " \
            f"{thr.orient_deg:g}° of the truth"
        out.append(f"**{mode_of(key).title if key in (*MODES, TRUTH_FREE) else key}** ({where}; {rule}):\n")
        out.append(headline_table(mine))
    out.append("Best first. Interval: Wilson's over scans (tracking pooled over sequences: bootstrap "
               "over sequences; the truth-free verdict: moving-block bootstrap over scans). *Against the next*: exact McNemar test on the scans both answered, "
               "Holm-adjusted within the table; *ahead* where p < 0.05. `headline.csv` has every "
               "dataset's table.\n")
    return "\n".join(out)
