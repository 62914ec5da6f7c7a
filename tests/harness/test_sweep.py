"""Parameter sweeps in run configurations: ``[[sweep]]`` grids become matcher labels."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from _paths import SCEN
from test_runner import make_dataset

from tfloc.cli.report import make_report as write_report
from tfloc.errors import ConfigError
from tfloc.harness.config import load_config
from tfloc.harness.runner import run
from tfloc.io.estimates import read_estimates


def write(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "run.toml"
    path.write_text('name = "sw"\ndatasets = ["data/scenarios/detail-1"]\n' + body)
    return path


def test_grid_is_a_cartesian_product_in_written_order(tmp_path):
    cfg = load_config(write(tmp_path, '''matchers = ["csm-corr"]
[params.tf]
window = 2
[[sweep]]
name = "tf"
grid = { straw_t = [0.95, 0.99], spacing = [0.5, 1.0] }
[[sweep]]
name = "tf-plus"
label = "tfp"
params = { seed = 3 }
grid = { spacing = [0.25] }
'''))
    assert [m.label for m in cfg.matchers] == [
        "csm-corr", "tf[straw_t=0.95,spacing=0.5]", "tf[straw_t=0.95,spacing=1.0]",
        "tf[straw_t=0.99,spacing=0.5]", "tf[straw_t=0.99,spacing=1.0]", "tfp[spacing=0.25]"]
    tf = cfg.matchers[2]
    assert tf.name == "tf" and tf.params == {"window": 2, "straw_t": 0.95, "spacing": 1.0}
    assert cfg.matchers[-1].params == {"seed": 3, "spacing": 0.25}
    assert "sweep" not in cfg.to_dict()  # the expanded matchers are recorded instead


def test_a_run_may_be_sweeps_only(tmp_path):
    cfg = load_config(write(tmp_path, '[[sweep]]\nname = "tf"\ngrid = { spacing = [0.5, 1] }\n'))
    assert [m.label for m in cfg.matchers] == ["tf[spacing=0.5]", "tf[spacing=1]"]


@pytest.mark.parametrize("body, message", [
    ('[[sweep]]\ngrid = { spacing = [1.0] }\n', r"sweep\[0\] must be a table with a matcher 'name'"),
    ('[[sweep]]\nname = "tf"\n', r"sweep\[0\]: 'grid' must be a non-empty table"),
    ('[[sweep]]\nname = "tf"\ngrid = { spacing = 1.0 }\n', r"grid\.spacing must be a non-empty list"),
    ('[[sweep]]\nname = "tf"\ngrid = { spacing = [1.0, 1.0] }\n', r"grid\.spacing lists a value twice"),
    ('[[sweep]]\nname = "tf"\ngrid = { spacing = [1.0] }\nstep = 2\n', r"unknown key\(s\) step"),
    ('matchers = ["tf[spacing=1.0]"]\n[[sweep]]\nname = "tf"\ngrid = { spacing = [1.0] }\n',
     "duplicate matcher labels"),
])
def test_bad_sweeps_name_the_file_and_the_entry(tmp_path, body, message):
    with pytest.raises(ConfigError, match=message) as info:
        load_config(write(tmp_path, body))
    assert "run.toml" in str(info.value)


def test_each_grid_point_is_its_own_matcher_in_results_and_report(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=3)
    path = tmp_path / "sweep.toml"
    path.write_text(f'''name = "sw"
out = "{tmp_path / 'run'}"
datasets = ["{ds}"]
jobs = 1
[[sweep]]
name = "toy_matchers:Stay"
label = "stay"
grid = {{ sleep_s = [0.0, 0.001] }}
''')
    out = run(load_config(path), progress=False)
    df = read_estimates(out)
    assert set(df.matcher) == {"stay[sleep_s=0.0]", "stay[sleep_s=0.001]"}
    assert len(df) == 6 and (df.status == "ok").all()
    files = write_report(out)
    text = files.report.read_text()
    assert "stay[sleep_s=0.0]" in text and "stay[sleep_s=0.001]" in text
    assert all(f.is_file() for f in files.figures)
    cfg = json.loads((out / "run.json").read_text())["config"]
    assert [m["params"] for m in cfg["matchers"]] == [{"sleep_s": 0.0}, {"sleep_s": 0.001}]


def test_a_dataset_entry_may_skip_the_first_scans_of_each_group(tmp_path):
    """A held-out selection: the scans after the first N of each group (a development split)."""
    from tfloc.harness.runner import make_tasks

    pool = SCEN / "office-pool"
    path = tmp_path / "held-out.toml"
    path.write_text(f'matchers = ["csm-corr"]\ndatasets = [{{ path = "{pool}", skip_per_group = 178 }}]\n')
    cfg = load_config(path)
    ids = [t.scan_id for t in make_tasks(cfg)]
    assert len(ids) == 9 * 2 and all(i.endswith(("-178", "-179")) for i in ids)
    limited = make_tasks(cfg.with_overrides(limit_per_group=1))
    assert [t.scan_id for t in limited] == [i for i in ids if i.endswith("-178")]
    with pytest.raises(ConfigError, match=r"datasets\[0\]\.skip_per_group must be a whole number"):
        path.write_text(f'matchers = ["tf"]\ndatasets = [{{ path = "{pool}", skip_per_group = -1 }}]\n')
        load_config(path)
