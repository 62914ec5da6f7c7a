""""Which localizer for which robot": statements computed from the leaderboards' rows, never
typed by hand. Each answers one question from one page's first run that has the data it needs
(pages.toml orders the runs), names that run, and says so where the data cannot answer.
Shares in %, CPU in ms per scan or step (median, one thread)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tfloc.core.modes import GLOBAL, SEQUENCE, SINGLE
from tfloc.core.rows.headline import POOLED
from tfloc.evaluation.headline import TRUTH_FREE

from .board import Board, Column
from .kinds import REAL, SIMULATED

#: how many points below the best share still count as "as good" for the cheapest-choice questions
WITHIN_POINTS = 1.0


@dataclass(frozen=True)
class Statement:
    """A question, its computed answer (Markdown inline: `code` for names) and the runs it reads."""

    question: str
    answer: str
    sources: tuple[str, ...] = ()


def first_run_columns(board: Board, real: bool | None = None) -> list[Column]:
    """The dataset columns (pooled left out) of the board's first run that has any, only real
    recordings (``real``), only simulated ones (``not real``) or all (``None``); a column whose
    dataset's kind is unknown (no readable ``scenario.json``) is in neither."""
    want = None if real is None else REAL if real else SIMULATED
    cols = [c for c in board.columns if c.scope != POOLED and not c.figure and c.measure != TRUTH_FREE
            and (want is None or c.kind == want)]
    return [c for c in cols if c.run == cols[0].run] if cols else []


def _cpu(board: Board, m: str, cols: list[Column]) -> float:
    """The largest median CPU of ``m`` over ``cols`` (NaN where a column has none)."""
    v = [board.cell(m, c).row.cpu_ms for c in cols if board.cell(m, c) and board.cell(m, c).row]
    return max(v) if v and not any(math.isnan(x) for x in v) else math.nan


def _best(board: Board, c: Column) -> float:
    return max((board.cell(m, c).value for m in board.matchers if board.cell(m, c)), default=math.nan)


def within_best(board: Board, cols: list[Column], points: float = WITHIN_POINTS) -> list[str]:
    """Matchers within ``points`` of the column's best share in every one of ``cols``."""
    return [m for m in board.matchers
            if all(board.cell(m, c) and board.cell(m, c).value >= _best(board, c) - points for c in cols)]


def _shares(board: Board, m: str, cols: list[Column]) -> str:
    return " / ".join(f"{board.cell(m, c).value:.1f}" for c in cols) + " %"


def _names(cols: list[Column]) -> str:
    return ", ".join(c.scope for c in cols)


def cheapest_as_good(board: Board, cols: list[Column], question: str, what: str) -> Statement:
    """The cheapest matcher within :data:`WITHIN_POINTS` of the best share on every column."""
    if not cols:
        return Statement(question, f"Not yet: no run of *{board.title}* has {what}.")
    run = cols[0].run
    ok = within_best(board, cols)
    priced = sorted((m for m in ok if not math.isnan(_cpu(board, m, cols))), key=lambda m: _cpu(board, m, cols))
    if not ok:
        best = "; ".join(f"{c.scope} {_best(board, c):.1f} %" for c in cols)
        return Statement(question, f"No matcher is within {WITHIN_POINTS:g} point of the best on every one of "
                                   f"{what} in `results/{run}/` (best: {best}).", (run,))
    if not priced:
        return Statement(question, f"{', '.join(f'`{m}`' for m in ok)} within {WITHIN_POINTS:g} point of the best on "
                                   f"every one of {what} in `results/{run}/`; the run has no CPU figure to "
                                   f"choose between them.", (run,))
    m = priced[0]
    others = ", ".join(f"`{o}` {_cpu(board, o, cols):.3g} ms" for o in priced[1:])
    rest = f"; also within it: {others}" if others else "; no other matcher is"
    return Statement(question, f"`{m}`: the cheapest matcher within {WITHIN_POINTS:g} point of the best share on "
                               f"every one of {what} ({_names(cols)}: {_shares(board, m, cols)}) at "
                               f"{_cpu(board, m, cols):.3g} ms CPU or less{rest}. "
                               f"From `results/{run}/`.", (run,))


def leader(board: Board, cols: list[Column], question: str, what: str) -> Statement:
    """Who ranks first on each column, and where the paired test separates it from the next."""
    if not cols:
        return Statement(question, f"Not yet: no run of *{board.title}* has {what}.")
    run = cols[0].run
    firsts = {c.key: next((m for m in board.matchers if board.cell(m, c) and board.cell(m, c).row
                           and board.cell(m, c).row.rank == 1), None) for c in cols}
    names = list(dict.fromkeys(v for v in firsts.values() if v))
    if len(names) == 1:
        m = names[0]
        ahead = [c for c in cols if board.cell(m, c).best]
        tied: dict[str, list[str]] = {}
        for c in cols:
            r = board.cell(m, c).row
            if r.verdict == "tied":
                tied.setdefault(r.next_matcher, []).append(c.scope)
        if len(ahead) == len(cols):
            sep = "the paired test puts it ahead of the next on every one"
        else:
            sep = f"the paired test puts it ahead of the next on {len(ahead)} of {len(cols)}" + "".join(
                f"; it does not separate it from `{o}` on {', '.join(s)}" for o, s in tied.items())
        cpu = _cpu(board, m, cols)
        cost = f", at {cpu:.3g} ms CPU or less" if not math.isnan(cpu) else ""
        return Statement(question, f"`{m}` ranks first on every one of {what} ({_names(cols)}: "
                                   f"{_shares(board, m, cols)}){cost}; {sep}. From `results/{run}/`.", (run,))
    per = "; ".join(f"{c.scope}: `{firsts[c.key]}`" + (" (ahead)" if firsts[c.key] and board.cell(firsts[c.key], c).best
                                                        else "") for c in cols)
    return Statement(question, f"No one matcher ranks first on all {what}: {per}. "
                               f"From `results/{run}/`.", (run,))


def most_often_near(board: Board, cols: list[Column], question: str, what: str) -> Statement:
    """The matcher within :data:`WITHIN_POINTS` of the best on the most columns, and its worst gap."""
    if not cols:
        return Statement(question, f"Not yet: no run of *{board.title}* has {what}.")
    run = cols[0].run
    near = {m: [c for c in cols if board.cell(m, c) and board.cell(m, c).value >= _best(board, c) - WITHIN_POINTS]
            for m in board.matchers}
    m = max(board.matchers, key=lambda k: (len(near[k]), -board.matchers.index(k)))
    gaps = [(_best(board, c) - board.cell(m, c).value, c.scope) for c in cols if board.cell(m, c)]
    gap, where = max(gaps)
    worst = f"; its largest gap to the best: {gap:.1f} points on {where}" if gap > WITHIN_POINTS else ""
    return Statement(question, f"`{m}` is within {WITHIN_POINTS:g} point of the best on {len(near[m])} of "
                               f"{len(cols)} {what}{worst}. From `results/{run}/`.", (run,))


def knows_when_lost(board: Board, question: str) -> Statement:
    """The tracker whose own confidence best detects its losses (the first run's pooled self-AUC
    column; :mod:`tfloc.evaluation.selfassess`), and the one whose confidence says least."""
    cols = [c for c in board.columns if c.figure == "self_auc"]
    if not cols:
        return Statement(question, "Not yet: no tracking run has a self-assessment (tfloc report on a run "
                                   "with truth).")
    c = cols[0]
    main = next(x for x in board.columns if x.run == c.run and x.scope == c.scope and not x.figure)
    # a detector needs both kinds of scan: trackers that track at least half of them
    have = sorted((m for m in board.matchers if board.cell(m, c) and board.cell(m, main)
                   and board.cell(m, main).value >= 50.0), key=lambda m: -board.cell(m, c).value)
    if not have:
        return Statement(question, f"No tracker of `results/{c.run}/` tracks half of its scans.", (c.run,))
    best, worst = have[0], have[-1]
    key = board.cell(best, c).row
    where = "pooled over its recordings" if c.scope == POOLED else c.scope
    return Statement(question, f"`{best}`: of the trackers that track at least half of the scans, its own "
                               f"confidence flags its losses best (self-assessment AUC "
                               f"{board.cell(best, c).value:.2f}, {where}; 0.5 is chance); least: `{worst}` "
                               f"({board.cell(worst, c).value:.2f}). The report's self-assessment table has the "
                               f"share of losses each catches at 1 % false alarms. From `results/{c.run}/`.",
                     (c.run,)) if key is not None else Statement(question, "Not yet.")


def statements(boards: dict[str, Board]) -> list[Statement]:
    """The section's statements from the leaderboards by page key (a missing page: "not yet")."""
    def b(key: str) -> Board:
        return boards.get(key) or Board(key, key, [], [])

    track, single, glob = b(SEQUENCE.page), b(SINGLE.page), b(GLOBAL.page)
    return [
        cheapest_as_good(track, first_run_columns(track, real=True), "Tracking a real robot",
                         "the real recordings"),
        knows_when_lost(track, "A tracker that knows when it is lost"),
        leader(single, first_run_columns(single, real=True), "The most accurate single scan on real logs",
               "the real logs"),
        cheapest_as_good(single, first_run_columns(single, real=True), "A single scan on a small CPU budget",
                         "the real logs"),
        leader(glob, first_run_columns(glob, real=True), "Without a guess, on a real building's map",
               "the real maps"),
        leader(glob, first_run_columns(glob, real=False), "Without a guess, in simulated offices",
               "the simulated offices"),
        leader(b("kidnap"), first_run_columns(b("kidnap")), "When the robot may be carried elsewhere",
               "the kidnapped sequences"),
        most_often_near(b("robustness"), first_run_columns(b("robustness")),
                        "On someone else's map or in a changed world", "map styles and changed worlds"),
    ]
