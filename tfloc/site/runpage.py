"""A run's page: its provenance from ``run.json`` (commit, versions, machine, sessions' dates),
its ``report.md``, ``timing.md`` and other notes rendered as HTML (``run.json`` read through
:mod:`tfloc.site.runs`; a malformed one shows as no provenance). The page works from disk: a
relative link or image of a note points at the file's place in the results root (the figures
stay where the run wrote them, nothing is copied), a link to a rendered note at its anchor, and
a link to nothing is dropped (its text kept)."""

from __future__ import annotations

import html
import os
from pathlib import Path
from urllib.parse import unquote, urlsplit

from tfloc.core.run import RunRecord

from .html import markdown, shell
from .runs import run_info

#: the notes a run page renders, in this order (any other top-level *.md follows)
NOTES = ("report.md", "timing.md", "NOTE.md", "robustness.md", "README.md")


def anchor(note: str) -> str:
    """The page anchor of a rendered note."""
    return "note-" + note.replace(".", "-").lower()


def provenance_html(run: RunRecord) -> str:
    """The run's provenance as a definition list (what ``run.json`` records)."""
    items = [("commit", (run.git.commit or "unknown") + (" (with uncommitted changes)" if run.git.dirty else "")),
             ("run", run.name or "")]
    if run.sessions:
        first, last = run.sessions[0].started, run.sessions[-1].ended or run.sessions[-1].started
        n = len(run.sessions)
        items.append(("dates", f"{first} → {last} ({n} session{'s' * (n != 1)})"))
    if run.exists:
        m = run.machine.to_dict()
        items.append(("machine", ", ".join(f"{k} {v}" for k, v in m.items() if v not in ("", None, "?"))))
    if run.versions:
        items.append(("versions", ", ".join(f"{k} {v}" for k, v in run.versions.items())))
    if run.matchers:
        items.append(("matchers", ", ".join(run.labels)))
    body = "".join(f"<dt>{html.escape(k)}</dt><dd>{html.escape(v)}</dd>" for k, v in items)
    return f'<section id="provenance"><h2>Provenance (run.json)</h2><dl class="prov">{body}</dl></section>'


def _retarget(url: str, run_dir: Path, page_dir: Path, rendered: set[str]) -> str | None:
    """Where a relative link of a note should point from the run's page (None: nowhere)."""
    parts = urlsplit(url)
    if parts.scheme or parts.netloc or url.startswith("#") or not parts.path:
        return url
    rel = unquote(parts.path)
    if rel in rendered:
        return "#" + anchor(rel)
    target = (run_dir / rel).resolve()
    if target.exists():
        return os.path.relpath(target, page_dir).replace(os.sep, "/")
    return None


def note_html(text: str, run_dir: Path, page_dir: Path, rendered: set[str]) -> str:
    """A note's Markdown as HTML, its relative links and images pointed as the module says."""
    md = markdown()
    tokens = md.parse(text)
    for tok in tokens:
        for child in tok.children or []:
            attr = "href" if child.type == "link_open" else "src" if child.type == "image" else None
            if attr is None:
                continue
            where = _retarget(str(child.attrGet(attr) or ""), run_dir, page_dir, rendered)
            if where is not None:
                child.attrSet(attr, where)
            elif child.type == "image":
                child.type, child.content, child.children = "text", f"[{child.content or 'figure'}: not in the run]", None
            else:
                child.attrSet(attr, "")
                child.type = "text"
                child.content = ""
                child.nesting = 0
        if tok.children:  # a dropped link's closing tag goes with it
            opened = 0
            for child in tok.children:
                if child.type == "link_open":
                    opened += 1
                elif child.type == "link_close":
                    if opened:
                        opened -= 1
                    else:
                        child.type, child.content, child.nesting = "text", "", 0
    return md.renderer.render(tokens, md.options, {})


def write_run_page(run_dir: Path, page_dir: Path, title: str, home: str, generator: str = "") -> Path:
    """``page_dir/index.html`` for the run in ``run_dir`` (``generator``: the identity of the code
    that draws it); returns its path."""
    page_dir.mkdir(parents=True, exist_ok=True)
    run = run_info(run_dir)
    notes = [n for n in NOTES if (run_dir / n).is_file()]
    notes += sorted(p.name for p in run_dir.glob("*.md") if p.name not in notes)
    rendered = set(notes)
    toc = " · ".join(f'<a href="#{anchor(n)}">{html.escape(n)}</a>' for n in notes)
    parts = [f"<h1>{html.escape(title)}</h1><p class=\"muted\"><code>results/{html.escape(run_dir.name)}/</code>"
             + (f" · {toc}" if toc else "") + " · <a href=\"#provenance\">provenance</a></p>"]
    for n in notes:
        body = note_html((run_dir / n).read_text(encoding="utf-8"), run_dir, page_dir, rendered)
        parts.append(f'<section class="report" id="{anchor(n)}"><p class="muted">{html.escape(n)}</p>{body}</section>')
    parts.append(provenance_html(run))
    out = page_dir / "index.html"
    out.write_text(shell(f"{title} — tfloc", "\n".join(parts), home, generator), encoding="utf-8")
    return out
