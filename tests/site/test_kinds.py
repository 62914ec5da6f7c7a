"""A dataset's kind (real recording or simulated) comes from its ``scenario.json``, never its
name: checked on every bundled dataset against today's names, and on a simulated dataset renamed
``real-…``, through the run's recorded directory and through ``data/scenarios/<name>``."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from _paths import ROOT, SCEN

from tfloc.io.rundir import run_of
from tfloc.io.scenario import read_scenario
from tfloc.site.kinds import REAL, SIMULATED, dataset_kind
from tfloc.site.runs import dataset_kinds, run_info

BUNDLED = sorted(p.parent for p in SCEN.glob("*/scenario.json"))


def _named_real(name: str) -> bool:
    """Today's names: ``real-…``, and the development split of the real global maps
    (``global-dev-real-<log>``: its real scans; ``…-sim`` is the same map's ray-cast scans)."""
    return name.startswith("real-") or (name.startswith("global-dev-real-") and not name.endswith("-sim"))


@pytest.mark.parametrize("d", BUNDLED, ids=lambda p: p.name)
def test_every_bundled_dataset_reads_as_its_name_says(d: Path) -> None:
    sc = read_scenario(d)
    kind = dataset_kind(sc.extra)
    assert kind == (REAL if _named_real(d.name) else SIMULATED), (d.name, kind)
    if kind == REAL:  # the recording it names is in the repository
        assert all((ROOT / f).is_file() for f in sc.extra["source"]["files"]), d.name


def test_both_kinds_are_bundled() -> None:
    kinds = [dataset_kind(read_scenario(d).extra) for d in BUNDLED]
    assert kinds.count(REAL) >= 10 and kinds.count(SIMULATED) >= 10


def test_an_explicit_kind_decides() -> None:
    recorded = {"source": {"files": ["data/real/aces/aces-corrected.log.gz"]}}
    assert dataset_kind(recorded) == REAL and dataset_kind({**recorded, "kind": "simulated"}) == SIMULATED
    assert dataset_kind({"kind": "real"}) == REAL and dataset_kind({"source": {"files": []}}) == SIMULATED
    assert dataset_kind({"kind": "nonsense"}) == SIMULATED


def _copy(src: str, dst: Path, **fields) -> Path:
    dst.mkdir(parents=True)
    doc = json.loads((SCEN / src / "scenario.json").read_text())
    (dst / "scenario.json").write_text(json.dumps({**doc, "name": dst.name, **fields}))
    return dst


def test_a_renamed_dataset_keeps_its_kind(tmp_path: Path) -> None:
    sim = _copy("seq-easy-a", tmp_path / "elsewhere" / "real-x")
    rec = _copy("real-aces-native", tmp_path / "elsewhere" / "seq-y")
    info = run_of({"datasets": {"real-x": str(sim), "seq-y": str(rec)}}, Path("run.json"))
    assert dataset_kinds(info, ["real-x", "seq-y", "unknown"]) == {"real-x": SIMULATED, "seq-y": REAL}


def test_a_dataset_the_run_did_not_record_is_looked_for_under_the_checkout(tmp_path: Path) -> None:
    _copy("seq-easy-a", tmp_path / "data" / "scenarios" / "real-z")
    moved = run_of({"datasets": {"real-z": "no/such/dir"}}, Path("run.json"))
    assert dataset_kinds(moved, ["real-z"], tmp_path) == {"real-z": SIMULATED}
    assert dataset_kinds(moved, ["real-z"]) == {}  # not found from here: unknown, not guessed from the name


def test_a_malformed_run_json_reads_as_an_empty_record(tmp_path: Path) -> None:
    (tmp_path / "run.json").write_text("{not json")
    assert not run_info(tmp_path).exists and run_info(tmp_path).datasets == ()
    (tmp_path / "run.json").write_text(json.dumps({"datasets": {"a": 3}}))
    assert not run_info(tmp_path).exists
    shutil.rmtree(tmp_path)
    assert not run_info(tmp_path).exists


def test_the_advice_reads_the_kind_the_run_records(tmp_path: Path) -> None:
    """A run of a simulated dataset named real-…: its rows carry the kind, and the real-robot
    advice does not read it (the same run with the dataset recorded as real does)."""
    from _site_results import TRACKING_CSV, _native_headline

    from tfloc.site.advice import first_run_columns
    from tfloc.site.board import headline_board
    from tfloc.site.pages import Page, RunRef
    from tfloc.site.rows import run_rows

    page = Page("tracking", "T", "", "", (RunRef("run", "run", ("sequence",)),))
    for src, kind in (("seq-easy-a", SIMULATED), ("real-aces-native", REAL)):
        root = tmp_path / kind
        (root / "run").mkdir(parents=True)
        (root / "run" / "tracking.csv").write_text(TRACKING_CSV)
        _native_headline(root / "run")
        sets = {n: str(_copy(src, tmp_path / kind / "sets" / n)) for n in ("real-a-native", "real-b-native")}
        (root / "run" / "run.json").write_text(json.dumps({"datasets": sets}))
        rr = run_rows(root, "run")
        assert rr.kinds == {"real-a-native": kind, "real-b-native": kind}
        board = headline_board(page, {"run": rr})
        real = [c.scope for c in first_run_columns(board, real=True)]
        assert real == (["real-a-native", "real-b-native"] if kind == REAL else []), kind
