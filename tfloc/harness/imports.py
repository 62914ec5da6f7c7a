"""tfloc's own modules and what each imports: the static import graph code identity is built on.

Every ``.py`` file of the packages ``tfloc`` and ``tfloc.baselines`` (``baselines/`` in the
repository) is a module with a dotted name; its imports of other tfloc modules are read from its
source (:mod:`ast`, at any depth: a function's lazy import runs too), relative imports resolved,
``from pkg import name`` counted as the module ``pkg.name`` where that is one. Importing a module
runs the ``__init__`` of every package above it, so those are part of what it imports.
:func:`closure` is every module a set of modules imports, directly or not: the code that can
decide what they compute. Nothing is imported to find it (the graph is read, not executed), so it
costs milliseconds and sees the files on disk, not a process's stale copies.
"""

from __future__ import annotations

import ast
import hashlib
import importlib.util
from collections.abc import Container, Iterable, Mapping
from functools import cache
from pathlib import Path

#: the packages whose files are tfloc's own code
PACKAGES = ("tfloc", "tfloc.baselines")


@cache
def _package_dir(package: str) -> Path:
    spec = importlib.util.find_spec(package)
    if spec is None or not spec.submodule_search_locations:
        raise ModuleNotFoundError(package)
    return Path(next(iter(spec.submodule_search_locations))).resolve()


@cache
def module_files() -> dict[str, Path]:
    """Module name → its file, for every module of :data:`PACKAGES` (a package by its
    ``__init__.py``)."""
    out: dict[str, Path] = {}
    for package in PACKAGES:
        root = _package_dir(package)
        for f in sorted(root.rglob("*.py")):
            rel = f.relative_to(root)
            if "__pycache__" in rel.parts:
                continue
            if package == "tfloc" and rel.parts[0] == "baselines":
                continue
            parts = [*package.split("."), *rel.with_suffix("").parts]
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = f
    return out


def file_key(module: str) -> str:
    """A module's file as a package path (``tfloc/paper/corners.py``,
    ``tfloc/baselines/karto.py``): the same on every install."""
    f = module_files()[module]
    pkg = next(p for p in sorted(PACKAGES, key=len, reverse=True)
               if module == p or module.startswith(p + "."))
    return f"{pkg.replace('.', '/')}/{f.relative_to(_package_dir(pkg)).as_posix()}"


def _parents(module: str) -> list[str]:
    parts = module.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def _read(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return ""


def imports_in(source: str, module: str, is_package: bool, known: Container[str]) -> set[str]:
    """The tfloc modules ``source`` (the text of ``module``, a package's ``__init__`` where
    ``is_package``) imports, at any depth, relative imports resolved; ``known``: the modules
    there are (``from pkg import name`` counts as the module ``pkg.name`` where that is one, else
    as the deepest known module the dotted name ``pkg`` names; the packages above a module are
    :func:`imports_of`'s)."""
    package = module if is_package else module.rpartition(".")[0]
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return set()
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [(a.name, None) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            targets = [(target, a.name) for a in node.names]
        else:
            continue
        for target, name in targets:
            if target.split(".")[0] != "tfloc":
                continue
            if name and f"{target}.{name}" in known:  # `from pkg import module`
                found.add(f"{target}.{name}")
                continue
            t = target
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t:
                found.add(t)
    return found


@cache
def _imports(module: str, mtime_ns: int) -> frozenset[str]:
    """The tfloc modules ``module``'s source names (``mtime_ns`` keys the cache to the file)."""
    path = module_files()[module]
    return frozenset(imports_in(_read(path), module, path.name == "__init__.py", module_files()))


def imports_of(module: str) -> frozenset[str]:
    """The tfloc modules ``module`` imports directly, and the packages above it (their
    ``__init__`` runs first)."""
    path = module_files()[module]
    try:
        mtime = path.stat().st_mtime_ns
    except OSError:
        mtime = 0
    return _imports(module, mtime) | {p for p in _parents(module) if p in module_files()}


def closure(roots: Iterable[str]) -> frozenset[str]:
    """Every tfloc module the modules ``roots`` import, directly or not, themselves included
    (a root outside tfloc's own code is left out: a plugin is identified by its distribution)."""
    files = module_files()
    todo = [r for r in roots if r in files]
    seen: set[str] = set(todo)
    while todo:
        for t in imports_of(todo.pop()):
            if t not in seen:
                seen.add(t)
                todo.append(t)
    return frozenset(seen)


def file_hashes(modules: Iterable[str]) -> dict[str, str]:
    """Package path → SHA-256 of the file's bytes, for ``modules`` (sorted by path)."""
    files = module_files()
    out = {}
    for m in modules:
        try:
            digest = hashlib.sha256(files[m].read_bytes()).hexdigest()
        except OSError:
            digest = "(unreadable)"
        out[file_key(m)] = digest
    return dict(sorted(out.items()))


def combined(hashes: Mapping[str, str]) -> str:
    """One SHA-256 over ``path → file hash`` in path order: the identity of a set of files."""
    h = hashlib.sha256()
    for k in sorted(hashes):
        h.update(f"{k}\0{hashes[k]}\0".encode())
    return h.hexdigest()
