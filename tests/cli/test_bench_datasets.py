"""``tfloc bench CONFIG --datasets``: a configuration's fixed subsample of datasets."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest
from _paths import ROOT

from tfloc.cli.bench import add_arguments, config_from_args
from tfloc.errors import ConfigError


def _args(*argv: str) -> argparse.Namespace:
    p = argparse.ArgumentParser()
    add_arguments(p)
    return p.parse_args(list(argv))


def test_datasets_keeps_the_named_ones_and_everything_else() -> None:
    full = config_from_args(_args(str(ROOT / "benchmarks/native.toml")))
    cfg = config_from_args(_args(str(ROOT / "benchmarks/native.toml"), "--datasets", "real-csail-native",
                                 "--out", "results/native-csail"))
    assert [d.name for d in cfg.datasets] == ["real-csail-native"]
    assert cfg.matchers == full.matchers and cfg.out == Path("results/native-csail")


def test_datasets_skips_follow_their_dataset() -> None:
    cfg = config_from_args(_args(str(ROOT / "benchmarks/dev/changed-world.toml"), "--datasets",
                                 "changed-clutter-25"))
    assert [d.name for d in cfg.datasets] == ["changed-clutter-25"]
    assert [n for _, n in cfg.skip_per_group] == [10]


@pytest.mark.parametrize("argv, message", [
    (["benchmarks/native.toml", "--datasets", "real-mars-native"], r"--datasets: real-mars-native not in run 'native'"),
    (["data/scenarios/detail-1", "--datasets", "detail-1"], r"--datasets selects datasets of a run configuration"),
])
def test_bad_datasets_are_refused(argv, message) -> None:
    argv = [str(ROOT / argv[0]), *argv[1:]]
    with pytest.raises(ConfigError, match=message):
        config_from_args(_args(*argv))
