"""The typed run: run.json's configuration read back as the value that wrote it, each matcher
resolved once, each dataset with its mode."""

from pathlib import Path

import pytest
from _paths import BENCHMARKS, SCEN

from tfloc.core.runconfig import RunConfig
from tfloc.errors import ConfigError, ResultsError
from tfloc.harness.config import load_study
from tfloc.io.rundir import RunDir

STUDIES = sorted(BENCHMARKS.glob("*.toml"))


@pytest.mark.parametrize("path", STUDIES, ids=[p.stem for p in STUDIES])
def test_every_studys_configuration_reads_back_from_its_dict(path: Path) -> None:
    cfg = load_study(path).run
    if cfg is None:
        pytest.skip("a scaling study (its own configuration)")
    again = RunConfig.from_dict(cfg.to_dict())
    assert again == cfg and again.to_dict() == cfg.to_dict()


def test_a_malformed_recorded_configuration_names_its_field() -> None:
    good = {"name": "r", "datasets": ["d"], "matchers": [{"label": "a", "name": "tf", "params": {}}]}
    assert RunConfig.from_dict(good).matchers[0].label == "a"
    for bad, field in (({**good, "datasets": "d"}, "config.datasets"), ({**good, "matchers": [3]}, "config.matchers"),
                       ({k: v for k, v in good.items() if k != "name"}, "'name'"), ({**good, "jobs": "x"}, "config")):
        with pytest.raises(ConfigError, match=field):
            RunConfig.from_dict(bad)


def test_run_json_is_one_typed_run(tmp_path: Path) -> None:
    doc = {"config": {"name": "r", "datasets": [str(SCEN / "office-pool"), "nowhere/seq"],
                      "matchers": [{"label": "fast", "name": "tf-plus-changed", "params": {}},
                                   {"label": "t", "name": "tf", "params": {"spacing": 0.5}}]},
           "datasets": {"office-pool": str(SCEN / "office-pool"), "seq": "nowhere/seq"},
           "declared": {"seq": {"mode": "sequence"}},
           "fingerprint": {"matchers": {"t": {"matcher": "tf", "params": {"spacing": 0.5, "straw_t": 0.95}}}}}
    rd = RunDir(tmp_path)
    rd.write_doc(doc)
    run = rd.info(required=True)
    assert run.config is not None and run.config.name == "r" and run.labels == ["fast", "t"]
    fast, t = run.matchers
    assert fast.base == "tf-plus" and fast.resolved == {}          # a preset, resolved once
    assert t.base == "tf" and t.resolved["straw_t"] == 0.95 and t.params == {"spacing": 0.5}
    assert run.mode("seq") == "sequence" and run.mode("office-pool") == "single"   # on disk, else recorded
    assert run.datasets_in(["seq", "office-pool"], "sequence") == {"seq"}
    rd.write_doc({**doc, "config": {**doc["config"], "jobs": "two"}})
    with pytest.raises(ResultsError, match="run.json: config"):
        rd.info()
