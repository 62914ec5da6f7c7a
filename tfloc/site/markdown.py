"""The leaderboards and statements as Markdown, for the README's and docs' generated blocks:
the text between ``<!-- tfloc:begin NAME -->`` and ``<!-- tfloc:end NAME -->`` is replaced by
block NAME (a page key: its full board; ``KEY-short``: the README's short table; ``cost``,
``cost-slopes``; ``advice``: the statements; ``targets``: the tracking targets, checked;
``truth-free``, ``self-assessment``: :mod:`tfloc.site.truthfree`; ``peers.RUN.M1.M2…``:
chosen matchers of one run side by side, :mod:`tfloc.site.peers`; ``matchers``: the project's
matchers from their declarations, :mod:`tfloc.site.matcher_table`, the one block that reads no
run: :data:`REGISTRY_BLOCKS`). The cells are the site's: the figure with its 95 % interval (bold
where the paired test puts the column's first ahead of the next) and the CPU per scan."""

from __future__ import annotations

import re

from tfloc.errors import ConfigError
from tfloc.report.mdtable import table

from .board import Board, Cell
from .collect import SiteData, run_note
from .cost import SLOPES, SLOPES_CSV
from .matcher_table import matchers_markdown
from .pages import COST
from .peers import is_peers, peers_markdown

BLOCK = re.compile(r"(<!-- tfloc:begin (?P<name>[\w.-]+) -->\n)(?P<body>.*?)(<!-- tfloc:end (?P=name) -->)", re.S)
ADVICE = "advice"
TARGETS = "targets"
TRUTH_FREE, SELF_ASSESSMENT = "truth-free", "self-assessment"
#: blocks drawn from the matcher registry, not from runs: rendered without a results root
REGISTRY_BLOCKS = {"matchers": matchers_markdown}
#: rows of a README table (``KEY-short``): the first matchers of its first column
SHORT_ROWS = 4


def _cell(c: Cell | None) -> str:
    if c is None:
        return "—"
    text = f"**{c.text}**" if c.best else c.text
    return f"{text} · {c.sub}" if c.sub else text


def board_markdown(board: Board, data: SiteData, short: bool = False) -> str:
    """One board as a Markdown table, with the runs it reads (and their state) below it."""
    reads = SLOPES_CSV if board.key == SLOPES else None
    notes = [run_note(data.runs.get(r), r, reads) for r in dict.fromkeys(c.run for c in board.columns)]
    page = next((p for p in data.pages if p.key == board.key.removesuffix("-short")), None)
    if page is not None and page.key != COST:
        have = {c.run for c in board.columns}
        notes += [run_note(data.runs.get(r.dir), r.dir) for r in page.runs
                  if r.dir not in have and (r.short or not short)]
    if not board.columns:
        return "_Not yet: " + "; ".join(notes or ["no run"]) + "._\n"
    one_run = len({c.run for c in board.columns}) == 1
    heads = ["matcher"] + [c.label if one_run else f"{c.label} ({c.run})" for c in board.columns]
    shown = board.matchers[:SHORT_ROWS] if short else board.matchers
    body = [[f"`{m}`"] + [_cell(board.cell(m, c)) for c in board.columns] for m in shown]
    out = table(heads, body, "l" + "r" * len(board.columns))
    more = len(board.matchers) - len(shown)
    if more:
        where = f" ({page.doc})" if page is not None and page.doc else ""
        notes.insert(0, f"{more} more matcher{'s' * (more != 1)} on the site and in the full table{where}")
    return out + "\n" + "; ".join(notes) + ".\n"


def advice_markdown(data: SiteData) -> str:
    """The statements as a list."""
    return "\n".join(f"- **{s.question}.** {s.answer}" for s in data.statements) + "\n"


def block(name: str, data: SiteData) -> str:
    """The Markdown of block ``name``."""
    if name in REGISTRY_BLOCKS:
        return REGISTRY_BLOCKS[name]()
    if name == ADVICE:
        return advice_markdown(data)
    if name == TARGETS:
        return data.targets
    if name == TRUTH_FREE:
        return data.truth_free
    if name == SELF_ASSESSMENT:
        return data.self_assessment
    if name in data.boards:
        return board_markdown(data.boards[name], data, short=name.endswith("-short"))
    if is_peers(name):
        return peers_markdown(name, data.root)
    raise ConfigError(f"unknown generated block {name!r}; known: {', '.join([ADVICE, TARGETS, TRUTH_FREE, SELF_ASSESSMENT, *REGISTRY_BLOCKS, *data.boards])}")


def block_names(text: str) -> list[str]:
    """The generated blocks a Markdown text holds, in order."""
    return [m.group("name") for m in BLOCK.finditer(text)]


def refresh(text: str, data: SiteData | None) -> str:
    """``text`` with every generated block rendered anew from ``data``; with ``data`` None only
    the :data:`REGISTRY_BLOCKS` (no run read), the others kept as they are."""
    def render(m: re.Match) -> str:
        if data is None and m.group("name") not in REGISTRY_BLOCKS:
            return m.group(0)
        return m.group(1) + block(m.group("name"), data) + m.group(4)

    return BLOCK.sub(render, text)
