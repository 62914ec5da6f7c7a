"""The rules docs/DESIGN.md states, each checked where a test can check it (the layer order and
cycles: test_layers.py; code identity: tests/harness/test_code_identity.py):

* the run directory is one typed store: no ``read_csv``/``to_csv`` outside it, a table file's
  name spelled only in ``io/tables.py``, ``run.json`` and ``estimates.csv`` only by the store;
* ``run.json`` is read into one typed record with no raw document;
* ``evaluation/`` is pure (no ``io`` import, no file opened); ``report/`` and ``site/`` only draw
  (``report/`` imports no harness module; ``site/`` only the study-file reader);
* nothing but ``core/modes.py`` spells a mode where a mode's properties are read.
"""

from __future__ import annotations

import ast
from dataclasses import fields
from pathlib import Path

import pytest
from _paths import ROOT
from test_layers import GRAPH, module_name, package_files

from tfloc.core.run import RunRecord
from tfloc.io import tables
from tfloc.io.table import Table

#: the store: the only modules that read or write a run directory's files as tables
STORE = {"tfloc/io/table.py", "tfloc/io/rundir.py", "tfloc/io/estimates.py"}
TABLE_NAMES = {t.name for t in vars(tables).values() if isinstance(t, Table)}


def _rel(f: Path) -> str:
    return f.relative_to(ROOT).as_posix()


def _code_strings(tree: ast.AST) -> list[ast.Constant]:
    """The string constants of a module that are not docstrings."""
    docs = {id(n.body[0].value) for n in ast.walk(tree)
            if isinstance(n, ast.Module | ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)
            and ast.get_docstring(n, clean=False) is not None}
    return [n for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)
            and id(n) not in docs]


SOURCES = {_rel(f): ast.parse(f.read_text()) for f in package_files()}


def test_no_csv_is_read_or_written_outside_the_store() -> None:
    bad = [f"{f}:{n.lineno}: .{n.attr}" for f, tree in SOURCES.items() if f not in STORE
           for n in ast.walk(tree) if isinstance(n, ast.Attribute) and n.attr in ("read_csv", "to_csv")]
    assert not bad, "tables read or written outside the store:\n" + "\n".join(bad)


def test_a_run_directorys_files_are_named_only_by_the_store() -> None:
    own = {"tfloc/io/tables.py": TABLE_NAMES, "tfloc/io/rundir.py": {"run.json", "estimates.csv"},
           "tfloc/io/estimates.py": {"estimates.csv"}}
    names = TABLE_NAMES | {"run.json", "estimates.csv"}
    bad = [f"{f}:{n.lineno}: {n.value!r}" for f, tree in SOURCES.items() for n in _code_strings(tree)
           if n.value in names and n.value not in own.get(f, set())]
    assert not bad, "a run directory's file named outside the store:\n" + "\n".join(bad)


def test_run_json_is_one_typed_record() -> None:
    assert "doc" not in {f.name for f in fields(RunRecord)}
    assert all(f.type not in ("dict", "Any") for f in fields(RunRecord))


@pytest.mark.parametrize("layer, allowed", [("tfloc.evaluation", ()), ("tfloc.report", ()),
                                            ("tfloc.site", ("tfloc.harness.config",))])
def test_pure_and_drawing_layers_stay_out_of_io_and_the_harness(layer: str, allowed: tuple[str, ...]) -> None:
    below = "tfloc.io" if layer == "tfloc.evaluation" else "tfloc.harness"
    bad = [f"{m} imports {t}" for m, targets in GRAPH.items() if m.startswith(layer + ".")
           for t in targets if (t == below or t.startswith(below + ".")) and t not in allowed]
    assert not bad, "\n".join(bad)


def test_evaluation_opens_no_file() -> None:
    files = {"open", "read_text", "write_text", "read_bytes", "write_bytes", "mkdir", "unlink"}
    bad = [f"{f}:{n.lineno}" for f, tree in SOURCES.items() if f.startswith("tfloc/evaluation/")
           for n in ast.walk(tree) if isinstance(n, ast.Call)
           and (isinstance(n.func, ast.Name) and n.func.id in files
                or isinstance(n.func, ast.Attribute) and n.func.attr in files)]
    assert not bad, "evaluation/ touches files:\n" + "\n".join(bad)


READERS_OF_MODES = ("tfloc/io/scenario.py", "tfloc/evaluation/headline.py", "tfloc/report/headline.py",
                    "tfloc/site/rows.py", "tfloc/harness/derive.py")


@pytest.mark.parametrize("module", READERS_OF_MODES)
def test_the_readers_of_a_mode_spell_none(module: str) -> None:
    from tfloc.core.modes import MODES, TRUTH_FREE

    keys = {*MODES, TRUTH_FREE.key}
    bad = [f"{module}:{n.lineno}: {n.value!r}" for n in _code_strings(SOURCES[module]) if n.value in keys]
    assert not bad, "a mode spelled where core/modes.py's Mode objects should be read:\n" + "\n".join(bad)


def test_the_checks_bite(tmp_path: Path) -> None:
    """A ``to_csv`` written into a report module, and a table's name spelled in a site module,
    are found."""
    tree = ast.parse("df.to_csv('x')\nname = 'headline.csv'\n")
    assert any(isinstance(n, ast.Attribute) and n.attr == "to_csv" for n in ast.walk(tree))
    assert any(n.value in TABLE_NAMES for n in _code_strings(tree))
    assert module_name(ROOT / "tfloc" / "report" / "report.py") == "tfloc.report.report"
