"""The architecture, checked: no module imports from a layer above its own, and no import cycles.

The layer order is written down once, here (docs/DESIGN.md shows the same picture). A module may
import from its own layer and the layers below it. ``tfloc/__init__.py`` is the public face: it
may import the layers it re-exports, and no module of the package imports it.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from _paths import ROOT

from tfloc.harness.imports import imports_in

#: Bottom to top. Each entry is a module or package prefix of ``tfloc``.
LAYERS = (
    "tfloc._kernel_cache",  # where numba caches the compiled kernels (one folder per source version)
    "tfloc.errors",      # the TflocError tree
    "tfloc.core",        # pose, laser, the map protocol, problem, matcher protocol + registry, parameters
    "tfloc.maps",        # vector and grid maps, ray casting, the distance field, the per-map cache
    "tfloc.paper",       # the paper's method (Algs. 1–5): `tf`
    "tfloc.tfplus",      # the project's own variant: `tf-plus`
    "tfloc.relocalize",  # global relocalization: `tf-global` (a turning-function place index)
    "tfloc.baselines",   # one module per baseline matcher (baselines/ in the repository)
    "tfloc.io",          # file formats: maps, scenario datasets, estimates, logs, bags, TUM
    "tfloc.datasets",    # the protocol's bins and sampler, simulated and real datasets, bag import
    "tfloc.evaluation",  # success/outcome rule, metrics, summaries, paper values, relations, guard
    "tfloc.harness",     # run configurations, tasks, the local and Dask executors
    "tfloc.report",      # report.md, figures, tables, the relations note, TUM export
    "tfloc.site",        # the static site and the README's generated blocks, from the run directories
    "tfloc.cli",         # one module per command
)


def module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[0] == "baselines":
        parts = ["tfloc", *parts]
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def package_files() -> list[Path]:
    return sorted([*(ROOT / "tfloc").rglob("*.py"), *(ROOT / "baselines").rglob("*.py")])


KNOWN = None


def imports_of(path: Path, source: str | None = None) -> set[str]:
    """Every ``tfloc`` module a file imports (at any depth, type-checking blocks included,
    relative imports resolved: :func:`tfloc.harness.imports.imports_in`, the graph code identity
    is built on)."""
    global KNOWN
    KNOWN = KNOWN or {module_name(f) for f in package_files()}
    return imports_in(path.read_text() if source is None else source, module_name(path),
                      path.name == "__init__.py", KNOWN)


def layer(module: str) -> int | None:
    for i, prefix in enumerate(LAYERS):
        if module == prefix or module.startswith(prefix + "."):
            return i
    return None


GRAPH = {module_name(f): imports_of(f) for f in package_files()}


def test_every_module_has_a_layer() -> None:
    loose = [m for m in GRAPH if m != "tfloc" and layer(m) is None]
    assert not loose, f"modules outside every layer (add them to LAYERS): {loose}"


def test_no_module_imports_from_a_layer_above() -> None:
    upward = [f"{m} ({LAYERS[layer(m)]}) imports {t} ({LAYERS[layer(t)]})"
              for m, targets in GRAPH.items() if m != "tfloc"
              for t in targets if t == "tfloc" or layer(t) > layer(m)]
    assert not upward, "upward imports:\n" + "\n".join(upward)


def test_no_import_cycles() -> None:
    state: dict[str, int] = {}
    stack: list[str] = []
    cycles: list[list[str]] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for t in sorted(GRAPH.get(m, ())):
            if t not in GRAPH or t == m:
                continue
            if state.get(t) == 1:
                cycles.append(stack[stack.index(t):] + [t])
            elif t not in state:
                visit(t)
        stack.pop()
        state[m] = 2

    for m in sorted(GRAPH):
        if m not in state:
            visit(m)
    assert not cycles, "import cycles:\n" + "\n".join(" → ".join(c) for c in cycles)


@pytest.mark.parametrize("bad", ["from tfloc.report.report import x", "from ..report import x",
                                 "import tfloc.cli"])
def test_the_check_bites(bad: str) -> None:
    """An upward import written into a maps module is found, however it is spelled."""
    f = ROOT / "tfloc" / "maps" / "vector.py"
    found = imports_of(f, f.read_text() + "\n" + bad + "\n")
    assert any(layer(t) > layer("tfloc.maps") for t in found)
