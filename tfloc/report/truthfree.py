"""The report's truth-free parts: the verdict's tables, its check against the truth, and every
tracker's self-assessment (its own confidence as a lost-detector, ``selfassess.csv``).

The verdict is made by ``tfloc verdict`` (:mod:`tfloc.harness.verdict`), the self-assessments by
the derive step (:mod:`tfloc.harness.derive`); this module reads their files through the store
and draws them. A verdict of other rows than the run's (stale) is not shown: the report says so.
On a dataset without truth nothing here prints a truth-based figure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import pandas as pd

from tfloc.core.rows.tracking import SelfAssessment
from tfloc.core.traits import confidence_of
from tfloc.evaluation.selfassess import FALSE_ALARM
from tfloc.io.rundir import RunDir
from tfloc.io.tables import SELFASSESS, VERDICT, VERDICT_AGREEMENT, VERDICT_FLAGS

from .mdtable import num, table


@dataclass(frozen=True)
class TruthFree:
    """What the tracking section draws from the truth-free files: the verdict and agreement
    tables and the flagged stretches (``None`` without a current verdict), the self-assessments,
    and a note (why there is no verdict, or ``""``)."""

    verdict: pd.DataFrame | None
    agreement: pd.DataFrame | None
    assessments: list[SelfAssessment] = field(default_factory=list)
    note: str = ""
    flags: pd.DataFrame | None = None


def load_truth_free(rd: RunDir, sequences: list[str], note: str = "") -> TruthFree:
    """The truth-free parts of a run with sequence datasets ``sequences`` (``note``: why its
    verdict is missing or stale, ``""`` when it is current)."""
    assessments = rd.read(SELFASSESS) if sequences else []
    if not sequences or note or not rd.has(VERDICT):
        return TruthFree(None, None, assessments, note or ("" if not sequences else
                                                           "no truth-free verdict yet (tfloc verdict RUN)"))
    agree = rd.frame(VERDICT_AGREEMENT) if rd.has(VERDICT_AGREEMENT) else None
    flags = rd.frame(VERDICT_FLAGS) if rd.has(VERDICT_FLAGS) else None
    return TruthFree(rd.frame(VERDICT), agree, assessments, "", flags)


#: flagged stretches listed per recording in the report (the rest: ``verdict_flags.csv``)
SHOWN_FLAGS = 5


def flags_text(flags: pd.DataFrame | None, scope: str) -> str:
    """The recording's flagged stretches in a line or two (its odometry and scan faults)."""
    if flags is None or scope == "all":
        return ""
    g = flags[flags["dataset"] == scope]
    if not len(g):
        return "Recording checks: no flagged stretch.\n"
    counts = g["kind"].value_counts()
    first = "; ".join(f"{r.kind} {r.first}…{r.last} ({r.scans} scans)" for r in g.head(SHOWN_FLAGS).itertuples())
    more = f"; {len(g) - SHOWN_FLAGS} more in `verdict_flags.csv`" if len(g) > SHOWN_FLAGS else ""
    return (f"Recording checks ({', '.join(f'{n} {k}' for k, n in counts.items())}; judged across, "
            f"marked `flagged` in `verdict_scans.csv.gz`): {first}{more}.\n")


def _ci(r) -> str:
    ci = "" if math.isnan(r.lo_pct) else f" [{r.lo_pct:.1f}–{r.hi_pct:.1f}]"
    return f"{r.score_pct:.1f}{ci}"


def verdict_table(v: pd.DataFrame, scope: str) -> str:
    """One recording's (or the pooled) verdict, best first, with the signal each figure comes from."""
    g = v[v["dataset"].astype(str) == scope].sort_values(["score_pct", "fit_pct"], ascending=False)
    body = [[i + 1, f"`{r.matcher}`", _ci(r), num(r.fit_pct, 1), num(r.consensus_pct, 1), num(r.agree_pct, 1),
             num(r.odometry_pct, 1), int(r.jumps),
             "—" if not r.restarts else f"{r.reconverged_pct:.0f} % of {int(r.restarts)}"]
            for i, r in enumerate(g.itertuples())]
    return table(["#", "tracker", "believed tracked % [95 % CI]", "map fit %", "consensus %", "agrees %",
                  "odometry disagrees %", "jumps", "restarts back"], body, "rlrrrrrrr")


def agreement_table(a: pd.DataFrame) -> str:
    """The verdict against the truth, per recording with truth."""
    body = [[r.dataset, int(r.trackers), num(r.rho, 2), f"`{r.truth_top}`", f"`{r.verdict_top}`",
             r.top + ("" if r.top == "same" else f" (p = {r.p_top:.2g})"), num(r.wrong_pct, 1),
             int(r.missed_losses), int(r.false_alarms), "agrees" if r.agrees else "**DISAGREES**"]
            for r in a.itertuples()]
    return table(["recording", "trackers", "Spearman ρ", "truth's top", "verdict's top", "top",
                  "scans judged wrongly %", "missed losses", "false alarms", ""], body, "lrrllrrrrl")


def selfassess_table(assessments: list[SelfAssessment], scope: str) -> str:
    """Every tracker's own confidence as a lost-detector on one scope, best AUC first."""
    mine = sorted((a for a in assessments if a.scope == scope), key=lambda a: 1.0 if math.isnan(a.auc) else -a.auc)
    body = [[f"`{a.matcher}`", f"`{a.key}`", confidence_of(a.matcher).about if confidence_of(a.matcher) else "",
             num(a.auc, 3), "—" if math.isnan(a.caught) else f"{100 * a.caught:.1f}", a.lost, a.scans]
            for a in mine]
    return table(["tracker", "confidence", "what it is", "AUC", f"lost caught at {100 * FALSE_ALARM:g} % "
                  "false alarms %", "lost scans", "scans"], body, "lllrrrr")


def truth_free_section(tf: TruthFree, blind: list[str]) -> str:
    """The tracking report's truth-free section: the verdict per recording, its check against
    the truth where there is one, and the self-assessment (``blind``: datasets without truth)."""
    out = ["## Without ground truth: the truth-free verdict and self-assessment\n"]
    if tf.verdict is None:
        out.append(f"_{tf.note or 'no truth-free verdict yet (tfloc verdict RUN)'}._\n")
    else:
        out.append("Each tracker judged from what a robot owner has — the scans, the map, the odometry and "
                   "the other trackers' answers, never the truth (docs/truth-free.md). *Believed tracked*: "
                   "agrees with the pose independent other trackers agree on where they do, else its map "
                   "fit is near the scan's best and its correction within the odometry's measured noise. "
                   "Interval: moving-block bootstrap over scans. Signals: *map fit* (returns within 5 cm of "
                   "the map), *consensus* (scans where the others agree), *agrees* (of those), *odometry "
                   "disagrees* (corrections beyond the envelope), *jumps* (> 1 m), *restarts back* (restarted "
                   "30 cm / 5° off, returned to its own trajectory).\n")
        scopes = list(dict.fromkeys(tf.verdict["dataset"].astype(str)))
        for s in (["all"] if "all" in scopes else []) + [s for s in scopes if s != "all"]:
            tag = " (no ground truth)" if s in blind else ""
            out += [f"**{'pooled' if s == 'all' else s}**{tag}:\n", verdict_table(tf.verdict, s),
                    flags_text(tf.flags, s)]
    if tf.agreement is not None and len(tf.agreement):
        bad = tf.agreement[~tf.agreement["agrees"].astype(bool)]
        out.append("**The verdict against the truth** (made with the truth hidden, then checked on the scans "
                   "with truth: Spearman ρ of the two rankings, the top tracker, the beliefs that are wrong; "
                   "*agrees* where ρ ≥ 0.8 and the top is the same or tied by the paired test):\n")
        out.append(agreement_table(tf.agreement))
        if len(bad):
            out.append(f"The truth-free verdict **disagrees with the truth** on {', '.join(bad['dataset'].astype(str))}: "
                       "there its ranking is not to be trusted.\n")
    if tf.assessments:
        scope = "all" if any(a.scope == "all" for a in tf.assessments) else tf.assessments[0].scope
        out.append(f"**Self-assessment** ({'pooled over the recordings with truth' if scope == 'all' else scope}): "
                   "each tracker's own confidence read as a lost-detector against *not tracked* on the scans "
                   "with truth. AUC 0.5 is chance, 1 a perfect detector; *caught*: the lost scans flagged at "
                   "the threshold that raises a false alarm on 1 % of tracked scans. Per recording: "
                   "`selfassess.csv`.\n")
        out.append(selfassess_table(tf.assessments, scope))
    return "\n".join(out)
