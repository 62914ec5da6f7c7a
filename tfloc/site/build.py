"""Writing the site: ``OUT/index.html`` from :func:`tfloc.site.collect.collect`, one page per
run under ``OUT/runs/NAME/`` (its figures linked where the run wrote them), and the README's and docs' generated blocks
refreshed from the same data. The only module of the package that writes files (besides the
screenshots)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from .collect import SiteData, collect
from .families import Family, family
from .html import index_html
from .markdown import block_names, refresh
from .runpage import write_run_page


def families_of(data: SiteData) -> dict[str, Family]:
    """Every matcher of the boards with its family."""
    return {m: family(m) for b in data.boards.values() for m in b.matchers}


def build_site(root: Path, out: Path, quick: bool = False, generator: str = "") -> SiteData:
    """Write the site for results root ``root`` into ``out`` (replaced), each page naming the
    identity of the code that drew it (``generator``); returns what it showed."""
    root, out = Path(root), Path(out)
    data = collect(root, quick=quick)
    if (out / "runs").is_dir():
        shutil.rmtree(out / "runs")
    out.mkdir(parents=True, exist_ok=True)
    labels = {r.dir: r.label for p in data.pages for r in p.runs}
    for name, rr in data.runs.items():
        if rr.exists:
            write_run_page(rr.path, out / "runs" / name, labels.get(name, name), "../../index.html", generator)
    shown = os.path.relpath(root.resolve(), out.resolve()).replace(os.sep, "/")
    (out / "index.html").write_text(index_html(data, families_of(data), f"the results root {shown}/", generator),
                                    encoding="utf-8")
    return data


def markdown_files(repo: Path) -> list[Path]:
    """The README and docs pages of ``repo`` that hold generated blocks."""
    files = [repo / "README.md", *sorted((repo / "docs").rglob("*.md"))]
    return [f for f in files if f.is_file() and block_names(f.read_text(encoding="utf-8"))]


def stale_markdown(files: list[Path], data: SiteData | None) -> list[Path]:
    """The ``files`` whose generated blocks are not what ``data`` gives (``None``: only the blocks
    drawn from the matcher registry are checked, :func:`tfloc.site.markdown.refresh`)."""
    texts = {f: f.read_text(encoding="utf-8") for f in files}
    return [f for f, text in texts.items() if refresh(text, data) != text]


def refresh_markdown(files: list[Path], data: SiteData | None) -> list[Path]:
    """Render every generated block of ``files`` anew (``data`` None: only the registry's);
    returns the files that changed."""
    changed = []
    for f in files:
        text = f.read_text(encoding="utf-8")
        new = refresh(text, data)
        if new != text:
            f.write_text(new, encoding="utf-8")
            changed.append(f)
    return changed
