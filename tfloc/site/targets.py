"""The tracking targets of ``tf-plus-track``, checked against the rows, never typed by hand: on
each real recording tracked at its native rate (the first of :data:`NATIVE_RUNS` that exists)
ahead of or tied with every other tracker of the run (each peer in its package's tracking
preset), no jump over 1 m, APE RMSE ≤ 4 cm, median CPU per step ≤ 0.3 ms and the cheapest
tracker with ≥ 95 % tracked; on the simulated conditions (``sequences``) ahead of or tied with
every peer. "Tied" and "behind" are the headline's paired tests (exact McNemar, Holm-adjusted)
read down its ranks: a tracker is behind every one ranked above the nearest separated pair
above it. Shares in %, APE in cm, CPU in ms per step (median over every step)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd

from tfloc.core.modes import SEQUENCE
from tfloc.core.rows.headline import POOLED, HeadlineRow
from tfloc.report.mdtable import table

from .kinds import SIMULATED

#: the tracker the targets are set for
TRACKER = "tf-plus-track"
#: the runs the native targets read, first found first
NATIVE_RUNS = ("native", "native-csail")
#: the simulated conditions' run
SIMULATED_RUN = "sequences"
APE_CM, JUMP_M, CPU_MS, TRACKS_PCT = 4.0, 1.0, 0.3, 95.0


@dataclass(frozen=True)
class Standing:
    """Where ``TRACKER`` stands in one headline table: ``first``, ``tied`` or ``behind``
    (``above``: the trackers the paired test puts ahead of it, best first)."""

    verdict: str
    rank: int
    value_pct: float
    above: tuple[str, ...] = ()


def standing(rows: list[HeadlineRow], me: str = TRACKER) -> Standing | None:
    """``me``'s standing in one table's ranked ``rows`` (None when it is not in the table)."""
    rows = sorted(rows, key=lambda r: r.rank)
    mine = next((r for r in rows if r.matcher == me), None)
    if mine is None:
        return None
    above = [r for r in rows if r.rank < mine.rank]
    cut = max((i for i, r in enumerate(above) if r.verdict == "ahead"), default=-1)
    if cut >= 0:
        return Standing("behind", mine.rank, mine.value_pct, tuple(r.matcher for r in above[:cut + 1]))
    return Standing("first" if mine.rank == 1 else "tied", mine.rank, mine.value_pct)


@dataclass(frozen=True)
class NativeCheck:
    """The targets on one native recording (``missed``: the targets it misses, by name)."""

    recording: str
    standing: Standing
    ape_cm: float
    jumps: int
    max_jump_m: float
    cpu_ms: float
    cheapest: str
    missed: tuple[str, ...]


def _standing_text(s: Standing) -> str:
    if s.verdict == "behind":
        return "behind " + ", ".join(f"`{m}`" for m in s.above[:3]) + (" …" if len(s.above) > 3 else "")
    return "first, ahead" if s.verdict == "first" else f"rank {s.rank}, tied with those above"


def native_checks(headline: list[HeadlineRow], tracking: pd.DataFrame, me: str = TRACKER) -> list[NativeCheck]:
    """The native targets per recording from a run's headline rows and ``tracking.csv``."""
    out = []
    for ds, g in tracking.groupby("dataset", sort=False):
        rows = [r for r in headline if r.scope == ds and r.mode == SEQUENCE.key]
        st, mine = standing(rows, me), g[g["matcher"] == me]
        if st is None or mine.empty:
            continue
        m = mine.iloc[0]
        good = g[(100 * g["tracked"] >= TRACKS_PCT) & (g["matcher"] != "odometry")]
        cheapest = str(good.sort_values(["cpu_ms_median", "matcher"]).iloc[0]["matcher"]) if len(good) else ""
        ape, jumps, cpu = 100 * float(m["ape_rmse_m"]), int(m["jumps"]), float(m["cpu_ms_median"])
        missed = [name for name, bad in (("rank", st.verdict == "behind"), ("APE", not ape <= APE_CM),
                                         ("jumps", jumps > 0), ("CPU", not cpu <= CPU_MS),
                                         ("cheapest", cheapest != me)) if bad]
        max_jump = float(m["max_jump_m"]) if not pd.isna(m["max_jump_m"]) else math.nan
        out.append(NativeCheck(str(ds), st, ape, jumps, max_jump, cpu, cheapest, tuple(missed)))
    return out


def simulated_line(headline: list[HeadlineRow], run: str, kinds: dict[str, str], me: str = TRACKER) -> str:
    """One sentence: on how many simulated sequences (``kinds``: dataset → kind,
    :mod:`tfloc.site.kinds`) ``me`` is first or tied, and behind whom."""
    scopes = [s for s in dict.fromkeys(r.scope for r in headline if r.mode == SEQUENCE.key)
              if s != POOLED and kinds.get(s) == SIMULATED]
    per = {s: standing([r for r in headline if r.scope == s], me) for s in scopes}
    per = {s: v for s, v in per.items() if v is not None}
    if not per:
        return f"Simulated conditions: not yet (no `{me}` rows in `results/{run}/`)."
    behind = {s: v for s, v in per.items() if v.verdict == "behind"}
    text = (f"Simulated conditions (`results/{run}/`): `{me}` first or tied with every peer on "
            f"{len(per) - len(behind)} of {len(per)} sequences")
    if behind:
        text += "; behind on " + "; ".join(f"{s} ({', '.join(f'`{m}`' for m in v.above[:2])})"
                                           for s, v in behind.items())
    return text + ("; **met**." if not behind else "; **missed** there.")


def targets_markdown(native: tuple[str, list[HeadlineRow], pd.DataFrame] | None,
                     simulated: tuple[str, list[HeadlineRow], dict[str, str]] | None, me: str = TRACKER) -> str:
    """The targets block: one row per native recording, then the simulated conditions' line
    (``simulated``: the run, its rows and its datasets' kinds)."""
    parts = []
    if native is None:
        parts.append(f"Native recordings: not yet (no run of {', '.join(NATIVE_RUNS)} with `tracking.csv` "
                     "and `headline.csv`).")
    else:
        run, rows, tracking = native
        checks = native_checks(rows, tracking, me)
        body = [[c.recording, f"{c.standing.value_pct:.1f} % ({_standing_text(c.standing)})", f"{c.ape_cm:.1f}",
                 f"{c.jumps}" + (f" (largest {c.max_jump_m:.2f} m)" if c.jumps else ""), f"{c.cpu_ms:.2f}",
                 f"`{c.cheapest}`" if c.cheapest else "none", "met" if not c.missed else
                 "**missed**: " + ", ".join(c.missed)] for c in checks]
        parts.append(f"`{me}` on each recording at its native rate (`results/{run}/`; targets: ahead of or "
                     f"tied with every peer, APE ≤ {APE_CM:g} cm, no jump > {JUMP_M:g} m, ≤ {CPU_MS:g} ms CPU "
                     f"per step, the cheapest tracker with ≥ {TRACKS_PCT:g} % tracked):\n")
        parts.append(table(["recording", "tracked", "APE cm", "jumps > 1 m", "CPU ms", f"cheapest ≥ {TRACKS_PCT:g} %",
                            "targets"], body, "llrrrll"))
    parts.append("\n" + (simulated_line(simulated[1], simulated[0], simulated[2], me) if simulated else
                         f"Simulated conditions: not yet (no `results/{SIMULATED_RUN}/` headline)."))
    return "\n".join(parts) + "\n"
