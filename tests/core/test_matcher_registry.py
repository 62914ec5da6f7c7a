"""The registry of the project's own matchers (``tfloc/core/registry.py``): each declared in its
module by a ``REGISTRY`` literal, read from the source without importing it, in an editable
install and a wheel's layout alike; a malformed declaration or a name declared twice is one line
naming the place; third parties' entry points are added beside them."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from collections.abc import Iterator
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path

import pytest
from _paths import ROOT

import tfloc.core.matcher as matcher
import tfloc.core.registry as registry
from tfloc.errors import RegistryError

GOOD = '"""A matcher."""\n\nREGISTRY = {NAME: {"class": "M", "summary": "s", "docs": "d.md"}}\n\n\nclass M:\n    pass\n'


@pytest.fixture()
def fresh() -> Iterator[None]:
    """The registry's caches emptied before and after (the test may point it elsewhere)."""
    registry.declarations.cache_clear()
    matcher._registry.cache_clear()
    yield
    registry.declarations.cache_clear()
    matcher._registry.cache_clear()


def _packages(monkeypatch: pytest.MonkeyPatch, tfloc_dir: Path, baselines_dir: Path) -> None:
    dirs = {"tfloc": [tfloc_dir], "tfloc.baselines": [baselines_dir]}
    monkeypatch.setattr(registry, "_package_dirs", lambda package: dirs[package])


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def test_every_declaration_is_registered_with_its_files_and_page() -> None:
    declared = registry.declarations()
    assert {d.name for d in declared} == set(matcher.available_matchers())  # no third party here
    for d in declared:
        assert matcher._registry()[d.name] == d.target
        assert (ROOT / d.path).is_file(), d
        assert (ROOT / "docs" / d.docs).is_file(), f"{d.name}: docs/{d.docs} does not exist"
        assert all((ROOT / f).exists() for f in d.files), d
    assert [d.path.startswith("baselines/") for d in declared] == sorted(
        d.path.startswith("baselines/") for d in declared)  # the project's own first


def test_the_project_declares_no_entry_point_of_its_own() -> None:
    """Its matchers are declared once, in their modules: not in pyproject.toml, not installed."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert matcher.GROUP not in project.get("entry-points", {})
    assert not [ep for ep in entry_points(group=matcher.GROUP)
                if getattr(ep.dist, "name", None) == "tfloc"]


def test_listing_the_matchers_imports_none_of_them() -> None:
    code = ("import sys, json\nfrom tfloc.core.matcher import available_matchers\n"
            "names = available_matchers()\n"
            "own = ('tfloc.paper', 'tfloc.tfplus', 'tfloc.relocalize', 'tfloc.baselines', "
            "'tfloc.core.tracker', 'open3d', 'kiss_icp', 'cv2')\n"
            "print(json.dumps([len(names), sorted(m for m in sys.modules if m.startswith(own))]))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    n, imported = json.loads(proc.stdout.strip().splitlines()[-1])
    assert n == len(registry.declarations()) and imported == []


def test_only_files_with_the_marker_are_parsed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                               fresh: None) -> None:
    _write(tmp_path / "tfloc" / "broken.py", "def f(:\n  REGISTRY = {\n")  # no marker: never parsed
    _write(tmp_path / "tfloc" / "doc.py", '"""Mentions\n    REGISTRY = {...}\nindented."""\n')
    _write(tmp_path / "tfloc" / "own.py", GOOD.replace("NAME", '"own-one"'))
    _packages(monkeypatch, tmp_path / "tfloc", tmp_path / "baselines")
    assert [(d.name, d.target, d.path) for d in registry.declarations()] == [
        ("own-one", "tfloc.own:M", "tfloc/own.py")]


def test_a_wheels_layout_reads_each_module_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                fresh: None) -> None:
    """A wheel installs baselines/ as tfloc/baselines/: found under both packages, read once."""
    _write(tmp_path / "tfloc" / "baselines" / "pkg" / "node.py", GOOD.replace("NAME", '"b-one"'))
    _write(tmp_path / "tfloc" / "paper" / "m.py", GOOD.replace("NAME", '"a-one"'))
    _packages(monkeypatch, tmp_path / "tfloc", tmp_path / "tfloc" / "baselines")
    got = [(d.name, d.target, d.path) for d in registry.declarations()]
    assert got == [("a-one", "tfloc.paper.m:M", "tfloc/paper/m.py"),
                   ("b-one", "tfloc.baselines.pkg.node:M", "baselines/pkg/node.py")]


def test_a_name_declared_in_two_modules_is_one_line_naming_both(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fresh: None) -> None:
    _write(tmp_path / "tfloc" / "a.py", GOOD.replace("NAME", '"twice"'))
    _write(tmp_path / "baselines" / "b.py", GOOD.replace("NAME", '"twice"'))
    _packages(monkeypatch, tmp_path / "tfloc", tmp_path / "baselines")
    with pytest.raises(RegistryError) as exc:
        registry.declarations()
    assert str(exc.value) == "matcher 'twice' is declared twice: in tfloc/a.py and in baselines/b.py"


def test_a_name_declared_by_a_module_and_an_entry_point_is_one_line(
        monkeypatch: pytest.MonkeyPatch, fresh: None) -> None:
    ep = EntryPoint(name="tf-plus", value="my_pkg.icp:Mine", group=matcher.GROUP)
    monkeypatch.setattr(matcher, "entry_points", lambda group: [ep])
    with pytest.raises(RegistryError) as exc:
        matcher.available_matchers()
    line = str(exc.value)
    assert "\n" not in line and "'tf-plus' is declared twice" in line
    assert "tfloc/tfplus/matcher.py" in line and "tf-plus = 'my_pkg.icp:Mine'" in line


def test_a_third_partys_entry_point_is_registered_beside_them(
        monkeypatch: pytest.MonkeyPatch, fresh: None) -> None:
    ep = EntryPoint(name="my-icp", value="my_pkg.icp:Mine", group=matcher.GROUP)
    monkeypatch.setattr(matcher, "entry_points", lambda group: [ep])
    assert matcher._registry()["my-icp"] == "my_pkg.icp:Mine"
    assert set(matcher.available_matchers()) == {"my-icp", *(d.name for d in registry.declarations())}


@pytest.mark.parametrize(("literal", "says"), [
    ('{"x-y": {"class": M, "summary": "s", "docs": "d.md"}}', "must be a literal"),
    ('{"x-y", "z"}', "must be a dict"),
    ('{"X_y": {"class": "M", "summary": "s", "docs": "d.md"}}', "lower-case words"),
    ('{"x-y": {"class": "M", "summary": "s"}}', "no 'docs'"),
    ('{"x-y": {"class": "M", "summary": "s", "docs": "d.md", "roster": ["a"]}}', "unknown field 'roster'"),
    ('{"x-y": {"class": "N", "summary": "s", "docs": "d.md"}}', "names class 'N', which tfloc/bad.py does not define"),
    ('{"x-y": {"class": "M", "summary": "s", "docs": "d.md", "rosters": "trackers"}}', "'rosters' must be a list"),
    ('{"x-y": {"class": "M", "summary": "", "docs": "d.md"}}', "'summary' must be a non-empty string"),
    ('{"x-y": {"class": "M", "summary": "s", "docs": "d"}}', "'docs' must name a page"),
    ('{"x-y": {"class": "M",\n', "cannot read its REGISTRY"),
])
def test_a_malformed_declaration_is_one_line_naming_the_file(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fresh: None, literal: str, says: str) -> None:
    _write(tmp_path / "tfloc" / "bad.py", f'"""Bad."""\n\nREGISTRY = {literal}\n\n\nclass M:\n    pass\n')
    _packages(monkeypatch, tmp_path / "tfloc", tmp_path / "baselines")
    with pytest.raises(RegistryError) as exc:
        registry.declarations()
    line = str(exc.value)
    assert "\n" not in line and line.startswith("tfloc/bad.py") and says in line, line
