"""Study files: every benchmarks/*.toml loads, none restates a default, the file it extends or a
preset's parameters, every matcher label is a name a verb accepts for the configuration it labels; ``extends`` merges tables key by key and never inherits the name; a study's
steps run after its run (``index`` before it) and make its tables."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from _paths import ROOT
from test_runner import make_dataset

from tfloc.core.presets import presets, resolve
from tfloc.core.thresholds import Thresholds
from tfloc.errors import ConfigError
from tfloc.harness.config import DEFAULT_STEPS, MatcherSpec, RunConfig, load_study, read_doc

FILES = sorted((ROOT / "benchmarks").rglob("*.toml"))
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "tests"), str(ROOT)])}


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.relative_to(ROOT / "benchmarks").as_posix())
def test_every_study_file_loads(path: Path) -> None:
    study = load_study(path)
    assert study.name and study.steps is not None
    assert (study.run is not None) == (study.kind == "bench")


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.relative_to(ROOT / "benchmarks").as_posix())
def test_every_label_is_a_name_for_the_configuration_it_labels(path: Path) -> None:
    study = load_study(path)
    if study.run is None:
        return
    wrong = []
    for m in study.run.matchers:
        try:
            named = resolve(m.label, {})
        except Exception as exc:  # noqa: BLE001 - every failure is listed
            named = (str(exc), {})
        if named != resolve(m.name, m.params):
            wrong.append(f"{m.label!r} reads as {named}, runs {resolve(m.name, m.params)}")
    assert not wrong, f"{path.name}: labels no verb reads as their configuration:\n" + "\n".join(wrong)


def _inherited(path: Path) -> dict:
    raw = tomllib.loads(path.read_text())
    return read_doc((path.parent / raw["extends"]).resolve()) if "extends" in raw else {}


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.relative_to(ROOT / "benchmarks").as_posix())
def test_no_study_file_restates_a_default_or_another_files_values(path: Path) -> None:
    raw, base = tomllib.loads(path.read_text()), _inherited(path)
    defaults = {"jobs": RunConfig.jobs, "timeout_s": RunConfig.timeout_s,
                "sequence_timeout_s": RunConfig.sequence_timeout_s, "limit_per_group": 0,
                "success": Thresholds().to_dict(), "steps": list(DEFAULT_STEPS), "kind": "bench"}
    restated = []
    for key, value in raw.items():
        if key == "extends":
            continue
        if key in base:
            if base[key] == value:
                restated.append(f"{key} (as in {raw['extends']})")
        elif key in defaults and value == defaults[key]:
            restated.append(f"{key} (the default)")
    name = raw.get("name", path.stem)
    if raw.get("name") == path.stem:
        restated.append("name (the file's name)")
    if raw.get("out") == f"results/{name}":
        restated.append("out (results/<name>)")
    assert not restated, f"{path.name} restates {', '.join(restated)}"


def _preset_values() -> dict[str, tuple[str, dict]]:
    return {n: resolve(n, {}) for n in presets()}


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.relative_to(ROOT / "benchmarks").as_posix())
def test_no_study_file_restates_a_presets_parameters(path: Path) -> None:
    raw = tomllib.loads(path.read_text())
    known = _preset_values()
    tables = [m for m in raw.get("matchers", []) if isinstance(m, dict) and m.get("params")]
    tables += [{"name": n, "params": p} for n, p in raw.get("params", {}).items()]
    for t in tables:
        got = resolve(t["name"], t["params"])
        same = [n for n, v in known.items() if v == got]
        assert not same, f"{path.name}: {t} is the preset {same[0]}: name it instead"


def test_extends_merges_tables_and_keeps_its_own_name(tmp_path: Path) -> None:
    (tmp_path / "base.toml").write_text(
        'name = "base"\nout = "results/base"\ndatasets = ["a"]\nmatchers = ["tf"]\nlimit_per_group = 5\n'
        'steps = ["timing", "report"]\n[params.tf]\nspacing = 0.5\nwindow = 2\n[success]\ndist_m = 0.05\n')
    (tmp_path / "child.toml").write_text('extends = "base.toml"\nlimit_per_group = 0\n[params.tf]\nwindow = 3\n')
    doc = read_doc(tmp_path / "child.toml")
    assert "name" not in doc and "out" not in doc and doc["limit_per_group"] == 0
    assert doc["params"] == {"tf": {"spacing": 0.5, "window": 3}} and doc["success"] == {"dist_m": 0.05}
    study = load_study(tmp_path / "child.toml")
    assert study.name == "child" and study.out == Path("results/child") and study.steps == ("timing", "report")
    assert study.run.matchers[0].params == {"spacing": 0.5, "window": 3} and study.run.success.dist_m == 0.05


def test_bad_extends_and_steps_are_one_line(tmp_path: Path) -> None:
    (tmp_path / "a.toml").write_text('extends = "b.toml"\n')
    (tmp_path / "b.toml").write_text('extends = "a.toml"\n')
    with pytest.raises(ConfigError, match="extends it back"):
        load_study(tmp_path / "a.toml")
    (tmp_path / "c.toml").write_text('extends = "nope.toml"\n')
    with pytest.raises(ConfigError, match="c.toml: extends 'nope.toml': no such file"):
        load_study(tmp_path / "c.toml")
    (tmp_path / "d.toml").write_text('datasets = ["x"]\nmatchers = ["tf"]\nsteps = ["report", "tables"]\n')
    with pytest.raises(ConfigError, match=r"d.toml: unknown step\(s\) tables; known: index, timing"):
        load_study(tmp_path / "d.toml")


def test_a_studys_steps_make_its_tables(tmp_path: Path, test_room, lms200) -> None:
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=2)
    study = tmp_path / "s.toml"
    study.write_text(f'datasets = ["{ds}"]\nout = "{tmp_path / "run"}"\n'
                     'matchers = [{ label = "stay", name = "toy_matchers:Stay" }]\n')
    run = lambda *a: subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", str(study), "--allow-import",  # noqa: E731
                                     "--jobs", "1", "--no-progress", *a], cwd=ROOT, env=ENV,
                                    capture_output=True, text=True, timeout=600)
    r = run("--no-steps")
    assert r.returncode == 0 and not (tmp_path / "run" / "report.md").exists(), r.stderr
    r = run()
    assert r.returncode == 0, r.stderr
    assert "already complete: 0 tasks run" in r.stderr and "tfloc report" in r.stderr
    assert (tmp_path / "run" / "report.md").read_text().count("## Headline") == 1


def test_every_step_a_study_may_declare_is_a_call_of_its_verb() -> None:
    from tfloc.cli import build_parser
    from tfloc.cli._study import STEP_CALLS
    from tfloc.harness.config import STEPS

    assert set(STEP_CALLS) == set(STEPS)
    cfg = RunConfig("r", Path("results/r"), (Path("data/scenarios/office-pool"),), (MatcherSpec.make("tf"),))
    parser = build_parser()
    for step in STEPS:
        for command, call in STEP_CALLS[step](cfg, quick=True):
            assert callable(call) and parser.parse_args(command.split())   # the same verb by hand
