"""The project's own matchers, declared in their modules and found without importing them.

A module of ``tfloc`` or ``tfloc.baselines`` (``baselines/`` in the repository) declares the
matchers it defines by one module-level literal, at the start of a line::

    REGISTRY = {"tf-plus-track": {"class": "TfPlusTracker", "summary": "a **tracker**: ...",
                                  "docs": "tracking.md", "rosters": ["trackers"]}}

``class`` names the class (or factory) that module defines; ``summary`` is its row of
docs/matchers.md (Markdown, links relative to docs/); ``docs`` its page under docs/; optional
``rosters`` the rosters of ``tfloc/rosters.toml`` it joins (:mod:`tfloc.harness.rosters`) and
``files`` the other files or folders of the repository it is made of (shown beside its module).
Why a literal: the registry reads every ``.py`` file of the folders the two packages are imported
from as text, and parses only the one statement of those holding :data:`MARKER`
(``ast.literal_eval``), so listing the matchers imports none of them (open3d, numba kernels), in
an editable install and a wheel alike (~0.05 s, once per process).
Third parties still register by entry points (:mod:`tfloc.core.matcher`).
"""

from __future__ import annotations

import ast
import importlib.util
import re
import tokenize
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from tfloc.errors import RegistryError

#: the assignment a declaring module holds at the start of a line (files without it are not parsed)
VARIABLE = "REGISTRY"
MARKER = f"\n{VARIABLE} = {{"
#: the packages scanned, with their folder in the repository
PACKAGES = {"tfloc.baselines": "baselines", "tfloc": "tfloc"}
REQUIRED = ("class", "summary", "docs")
OPTIONAL = ("rosters", "files")
#: what a literal is made of (``ast.literal_eval``'s nodes; no names, calls or f-strings)
LITERAL_NODES = (ast.Constant, ast.Dict, ast.List, ast.Tuple, ast.Set, ast.UnaryOp, ast.unaryop,
                 ast.expr_context)
NAME = re.compile(r"[a-z][a-z0-9]*(-[a-z0-9]+)*")


@dataclass(frozen=True)
class Declaration:
    """One matcher a module declares: ``name`` → ``module:attr``; ``path`` the declaring file as
    the repository names it (``baselines/o3d_icp.py``, ``tfloc/paper/matcher.py``)."""

    name: str
    module: str
    attr: str
    summary: str
    docs: str
    rosters: tuple[str, ...]
    files: tuple[str, ...]
    path: str

    @property
    def target(self) -> str:
        """``module:attr``, as an entry point names its class."""
        return f"{self.module}:{self.attr}"


def _package_dirs(package: str) -> list[Path]:
    """The folders the package ``package`` is imported from (found, not imported)."""
    spec = importlib.util.find_spec(package)
    return [Path(p) for p in (spec.submodule_search_locations or [])] if spec else []


def source_files() -> dict[str, Path]:
    """Module name → file, for every ``.py`` file of ``tfloc`` and ``tfloc.baselines`` (a wheel
    puts ``baselines/`` inside ``tfloc/``, the repository beside it: each module once)."""
    out: dict[str, Path] = {}
    for package in PACKAGES:
        for root in _package_dirs(package):
            for f in sorted(root.rglob("*.py")):
                rel = f.relative_to(root).with_suffix("")
                if "__pycache__" in rel.parts:
                    continue
                parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
                out.setdefault(".".join((package, *parts)), f)
    return out


def repo_path(module: str, file: Path) -> str:
    """The repository path of ``module``'s ``file`` (``tfloc.baselines.x``:
    ``baselines/x.py``)."""
    for package, folder in PACKAGES.items():
        if module == package or module.startswith(package + "."):
            parts = module.split(".")[len(package.split(".")):]
            if file.name == "__init__.py":
                parts.append("__init__")
            return "/".join((folder, *parts)) + ".py"
    return file.as_posix()


def _statement(text: str, where: str) -> tuple[str, int] | None:
    """The source of the ``REGISTRY = {...}`` statement of a module's ``text`` and its line
    (None: there is none). Only that statement is tokenized, not the whole module."""
    if text.startswith(MARKER[1:]):
        start = 0
    elif (at := text.find(MARKER)) >= 0:
        start = at + 1
    else:
        return None
    line = text.count("\n", 0, start) + 1
    rest = text[start:].splitlines(keepends=True)
    try:
        for tok in tokenize.generate_tokens(iter(rest).__next__):
            if tok.type == tokenize.NEWLINE:
                return "".join(rest[:tok.end[0]]), line
    except tokenize.TokenError:
        raise RegistryError(f"{where}:{line}: cannot read its {VARIABLE}: a bracket is not "
                            "closed") from None
    except SyntaxError as exc:
        raise RegistryError(f"{where}:{line}: cannot read its {VARIABLE}: {exc.msg}") from None
    return "".join(rest), line


def _literal(text: str, where: str) -> dict | None:
    """The value of the module-level ``REGISTRY = {...}`` of a module's ``text`` (None: none)."""
    found = _statement(text, where)
    if found is None:
        return None
    source, line = found
    try:
        node = ast.parse(source).body[0]
    except SyntaxError as exc:
        raise RegistryError(f"{where}:{line}: cannot read its {VARIABLE}: {exc.msg}") from None
    try:
        value = ast.literal_eval(node.value)
    except ValueError:
        walk = ast.walk(node.value)
        bad = next((n for n in walk if not isinstance(n, LITERAL_NODES)), node.value)
        raise RegistryError(f"{where}:{line + getattr(bad, 'lineno', 1) - 1}: {VARIABLE} must be a "
                            f"literal (strings, lists, dicts), not {ast.unparse(bad)!r}") from None
    if not isinstance(value, dict):
        raise RegistryError(f"{where}:{line}: {VARIABLE} must be a dict (matcher name → its "
                            "declaration)")
    return value


def _defines(text: str, name: str) -> bool:
    """Whether a module's ``text`` defines ``name`` at its top level (``class``, ``def`` or an
    assignment at the start of a line)."""
    return re.search(rf"^(?:class|def)\s+{re.escape(name)}\b|^{re.escape(name)}\s*[:=]", text,
                     flags=re.M) is not None


def _strings(value: object, field: str, where: str) -> tuple[str, ...]:
    if not isinstance(value, list | tuple) or not all(isinstance(v, str) and v for v in value):
        raise RegistryError(f"{where}: {field!r} must be a list of names")
    return tuple(value)


def _declaration(name: object, decl: object, module: str, path: str, text: str) -> Declaration:
    """One entry of a module's ``REGISTRY``, checked (one line naming the file and the name)."""
    where = f"{path}: {VARIABLE}[{name!r}]"
    if not isinstance(name, str) or not NAME.fullmatch(name):
        raise RegistryError(f"{where}: a matcher name is lower-case words joined by '-'")
    if not isinstance(decl, dict):
        raise RegistryError(f"{where}: must be a dict with {', '.join(map(repr, REQUIRED))}")
    unknown = sorted(set(decl) - {*REQUIRED, *OPTIONAL})
    missing = [k for k in REQUIRED if k not in decl]
    if unknown or missing:
        what = [f"unknown field {k!r}" for k in unknown] + [f"no {k!r}" for k in missing]
        fields = ", ".join((*REQUIRED, *OPTIONAL))
        raise RegistryError(f"{where}: {', '.join(what)} (fields: {fields})")
    for k in REQUIRED:
        if not isinstance(decl[k], str) or not decl[k].strip():
            raise RegistryError(f"{where}: {k!r} must be a non-empty string")
    if not _defines(text, decl["class"]):
        raise RegistryError(f"{where}: names class {decl['class']!r}, which {path} does not define")
    if not decl["docs"].endswith(".md"):
        raise RegistryError(f"{where}: 'docs' must name a page under docs/ (e.g. 'tracking.md')")
    return Declaration(name, module, decl["class"], " ".join(decl["summary"].split()), decl["docs"],
                       _strings(decl.get("rosters", []), "rosters", where),
                       _strings(decl.get("files", []), "files", where), path)


@cache
def declarations() -> tuple[Declaration, ...]:
    """Every matcher the project's modules declare: tfloc's own first, then the baselines, each
    in name order (read once per process). A name declared twice is a :class:`RegistryError`
    naming both files."""
    found: dict[str, Declaration] = {}
    files = source_files()
    for module in sorted(files):
        text = files[module].read_text(encoding="utf-8")
        path = repo_path(module, files[module])
        for name, decl in (_literal(text, path) or {}).items():
            d = _declaration(name, decl, module, path, text)
            if d.name in found:
                first = found[d.name].path
                raise RegistryError(f"matcher {d.name!r} is declared twice: in {first} and in "
                                    f"{path}")
            found[d.name] = d
    return tuple(sorted(found.values(), key=lambda d: (d.path.startswith("baselines/"), d.name)))
