"""The headline section that opens every ``report.md`` (and ``headline.csv`` beside it): one
ranked table per mode of the run, pooled over its datasets of that mode (or its one dataset),
from :mod:`tfloc.evaluation.headline`. The README and the site print the same rows."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.headline import POOLED, HeadlineRow, headline, headline_frame

from .mdtable import num, table

#: how a mode's table is titled
TITLES = {"single": "A single scan from a rough guess", "scan-to-scan": "Scan to scan",
          "sequence": "Tracking along a sequence", "global": "A single scan without a guess (global)"}


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
    unit = "CPU ms/step" if first.mode == "sequence" else "CPU ms/scan"
    body = [[r.rank, f"`{r.matcher}`", interval(r), num(r.error_cm, 2), num(r.cpu_ms, 2), r.n, verdict(r)]
            for r in rows]
    return table(["#", "matcher", f"{first.measure} % [95 % CI]", f"{first.error} (cm)",
                  f"{unit} (median)", "scans", "against the next"], body, "rlrrrrl")


def top_scope(rows: list[HeadlineRow], mode: str) -> str:
    """The scope a report shows for ``mode``: the pooled table, else its one dataset."""
    scopes = [r.scope for r in rows if r.mode == mode]
    return POOLED if POOLED in scopes else scopes[0]


def headline_section(p: pd.DataFrame, modes: dict[str, str], thr: Thresholds, run_dir: Path) -> str:
    """The report's opening section; writes ``run_dir/headline.csv`` (every table: each dataset,
    and each mode pooled)."""
    rows = headline(p, modes, thr)
    headline_frame(rows).to_csv(run_dir / "headline.csv", index=False, float_format="%.6g")
    if not rows:
        return "## Headline\n\n_No scan of this run has ground truth: nothing to rank._\n"
    out = ["## Headline\n"]
    for mode in dict.fromkeys(r.mode for r in rows):
        scope = top_scope(rows, mode)
        mine = [r for r in rows if r.mode == mode and r.scope == scope]
        names = sorted({d for d, m in modes.items() if m == mode and d in set(p["dataset"])})
        where = f"pooled over {', '.join(names)}" if scope == POOLED else scope
        out.append(f"**{TITLES.get(mode, mode)}** ({where}; {mine[0].measure}: within "
                   f"{thr.dist_m * 100:g} cm and {thr.orient_deg:g}° of the truth):\n")
        out.append(headline_table(mine))
    out.append("Best first. Interval: Wilson's over scans (tracking pooled over sequences: bootstrap "
               "over sequences). *Against the next*: exact McNemar test on the scans both answered, "
               "Holm-adjusted within the table; *ahead* where p < 0.05. `headline.csv` has every "
               "dataset's table.\n")
    return "\n".join(out)
