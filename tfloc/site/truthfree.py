"""The truth-free verdict's validation and the trackers' self-assessment, as the docs' generated
blocks ``truth-free`` and ``self-assessment``: from the runs' ``verdict_agreement.csv`` and
``selfassess.csv`` (read by :mod:`tfloc.site.collect`), each recording marked *development* (a
dataset of the development study :data:`DEV_STUDY`, on which the verdict's rules were chosen) or
*held out*. Pure: reads no file."""

from __future__ import annotations

import math

import pandas as pd

from tfloc.report.mdtable import num, table

#: the study file that declares the development split (its datasets)
DEV_STUDY = "benchmarks/dev/truth-free.toml"
#: the runs whose verdicts are checked against the truth (every bundled recording with truth once;
#: native-csail, make bench's subsample of native, would repeat its MIT CSAIL row)
RUNS = ("native", "sequences")


def agreement_markdown(tables: dict[str, pd.DataFrame], dev: set[str]) -> str:
    """Per run and recording with truth: the verdict's ranking against the truth's (``tables``:
    run → its ``verdict_agreement.csv``; ``dev``: the development datasets)."""
    if not tables:
        return "_Not yet: no run has a truth-free verdict (tfloc verdict RUN)._\n"
    body, held = [], []
    for run, a in tables.items():
        for r in a.itertuples():
            split = "development" if r.dataset in dev else "held out"
            if split == "held out":
                held.append(bool(r.agrees))
            top = r.top + ("" if r.top == "same" else f" (p = {r.p_top:.2g})")
            body.append([r.dataset, f"`results/{run}/`", split, int(r.trackers), num(r.rho, 2),
                         f"`{r.truth_top}`", f"`{r.verdict_top}`", top, num(r.wrong_pct, 1),
                         "agrees" if r.agrees else "**disagrees**"])
    out = table(["recording", "run", "split", "trackers", "Spearman ρ", "truth's top", "verdict's top",
                 "top", "scans judged wrongly %", ""], body, "lllrrlllrl")
    summary = (f"Held out: the verdict agrees with the truth on {sum(held)} of {len(held)} recordings "
               "(ρ ≥ 0.8 and the same top tracker or one the paired test ties with it)." if held else
               "No held-out recording has a verdict yet.")
    return out + "\n" + summary + "\n"


def selfassess_markdown(tables: dict[str, pd.DataFrame]) -> str:
    """Each tracker's self-assessment pooled over each run's recordings with truth (``tables``:
    run → its ``selfassess.csv``): AUC and the share of losses caught at 1 % false alarms."""
    runs = [r for r in RUNS if r in tables] or list(tables)
    if not runs:
        return "_Not yet: no run has a self-assessment (tfloc report on a tracking run with truth)._\n"
    pooled = {r: (t[t["scope"] == "all"] if (t["scope"] == "all").any() else t) for r, t in ((r, tables[r]) for r in runs)}
    matchers = list(dict.fromkeys(m for t in pooled.values() for m in t["matcher"]))

    def cell(run: str, m: str) -> str:
        g = pooled[run][pooled[run]["matcher"] == m]
        if not len(g):
            return "—"
        r = g.iloc[0]
        caught = "—" if math.isnan(r["caught"]) else f"{100 * r['caught']:.0f} %"
        return f"{num(r['auc'], 2)} · {caught}"

    def key(m: str) -> float:
        g = pooled[runs[0]][pooled[runs[0]]["matcher"] == m]
        return -float(g["auc"].iloc[0]) if len(g) and not math.isnan(g["auc"].iloc[0]) else 1.0

    matchers.sort(key=key)
    keys = {m: str(next(t.loc[t["matcher"] == m, "key"].iloc[0] for t in pooled.values() if (t["matcher"] == m).any()))
            for m in matchers}
    body = [[f"`{m}`", f"`{keys[m]}`"] + [cell(r, m) for r in runs] for m in matchers]
    return table(["tracker", "confidence"] + [f"`results/{r}/` AUC · caught" for r in runs], body,
                 "ll" + "r" * len(runs)) + "\nAUC of the tracker's own confidence against *not tracked* (0.5 = " \
        "chance), pooled over each run's recordings with truth; caught = the lost scans it flags at 1 % " \
        "false alarms.\n"
