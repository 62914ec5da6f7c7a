"""The site's pages and the run directories each reads, from ``pages.toml`` beside this module:
the one place that maps a leaderboard to its runs (see that file's header for the fields)."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

from tfloc.errors import ConfigError

PAGES_FILE = Path(__file__).with_name("pages.toml")
#: the page built from the other pages' runs (CPU per scan) and the scaling study's slopes
COST = "cost"
#: ``make quick``'s run of DIR is DIR + this
QUICK_SUFFIX = "-quick"


def quick_name(name: str) -> str:
    """The quick variant of a run's name or directory: ``NAME-quick``; a study that is already a
    quick one (``sequences-quick``, ``scaling-quick``) keeps its name, so that ``tfloc bench
    --quick`` writes it where ``tfloc site --only-quick`` reads every quick run. The one copy of
    the rule: the bench verb and the site both call it."""
    return name if name.endswith(QUICK_SUFFIX) else f"{name}{QUICK_SUFFIX}"


@dataclass(frozen=True)
class RunRef:
    """One run directory of a page: ``dir`` under the results root, the headline ``modes`` it
    gives the page, and whether its top column goes into the README's short table."""

    dir: str
    label: str
    modes: tuple[str, ...]
    short: bool = False


@dataclass(frozen=True)
class Page:
    """One leaderboard: its anchor ``key``, heading, one paragraph, docs page and runs."""

    key: str
    title: str
    about: str
    doc: str
    runs: tuple[RunRef, ...]


def _run(body: dict, where: str) -> RunRef:
    try:
        return RunRef(str(body["dir"]), str(body.get("label", body["dir"])),
                      tuple(str(m) for m in body.get("modes", ())), bool(body.get("short", False)))
    except KeyError as exc:
        raise ConfigError(f"{where}: a [[page.run]] without {exc.args[0]!r}") from None


def load_pages(path: Path = PAGES_FILE, quick: bool = False) -> list[Page]:
    """Every page of ``path`` in order (``quick``: each run directory's ``-quick`` variant)."""
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read the site's pages ({exc})") from None
    out = []
    for body in doc.get("page", []):
        missing = [k for k in ("key", "title") if k not in body]
        if missing:
            raise ConfigError(f"{path}: a [[page]] without {', '.join(missing)}")
        runs = [_run(r, str(path)) for r in body.get("run", [])]
        if quick:  # each quick run once: the cost page reads scaling and scaling-quick, both scaling-quick
            named: dict[str, RunRef] = {}
            for r in runs:
                d = quick_name(r.dir)
                if d not in named or r.dir == d:  # the entry naming the quick run itself keeps its label
                    named[d] = RunRef(d, r.label, r.modes, r.short)
            runs = list(named.values())
        out.append(Page(str(body["key"]), str(body["title"]), str(body.get("about", "")),
                        str(body.get("doc", "")), tuple(runs)))
    keys = [p.key for p in out]
    if len(set(keys)) != len(keys):
        raise ConfigError(f"{path}: page keys repeat: {keys}")
    return out


def page(pages: list[Page], key: str) -> Page | None:
    """The page called ``key``, if any."""
    return next((p for p in pages if p.key == key), None)
