"""Rosters: a study names a line-up once (``tfloc/rosters.toml``) and may extend it."""

from __future__ import annotations

from pathlib import Path

import pytest

from tfloc.errors import ConfigError
from tfloc.harness.config import load_config, parse_matchers
from tfloc.harness.rosters import expand, rosters


def _study(tmp_path: Path, matchers: str) -> Path:
    f = tmp_path / "s.toml"
    f.write_text(f'name = "s"\ndatasets = ["data/scenarios/detail-1"]\nmatchers = {matchers}\n')
    return f


def test_a_roster_by_name_is_its_matchers(tmp_path: Path) -> None:
    cfg = load_config(_study(tmp_path, '"single-scan"'))
    assert [m.label for m in cfg.matchers] == list(rosters()["single-scan"])


def test_a_study_extends_a_roster_in_place(tmp_path: Path) -> None:
    cfg = load_config(_study(tmp_path, '["odometry", "@trackers", "tf-plus"]'))
    labels = [m.label for m in cfg.matchers]
    assert labels[0] == "odometry" and labels[-1] == "tf-plus"
    assert labels.count("odometry") == 1 and set(rosters()["trackers"]) <= set(labels)


def test_an_unknown_roster_is_one_line_naming_it(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="no roster 'trackerz'"):
        load_config(_study(tmp_path, '["@trackerz"]'))
    with pytest.raises(ConfigError, match="no roster"):
        parse_matchers(["@nope"], {}, "--matchers")


def test_every_roster_name_is_a_matcher_or_preset() -> None:
    from tfloc.core.matcher import factory_of

    for name, members in rosters().items():
        for m in members:
            factory_of(m)  # raises on an unknown name
        assert len(set(members)) == len(members), name
    assert expand("trackers", "x") == list(rosters()["trackers"])
