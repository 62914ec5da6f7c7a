"""Rosters: a study names a line-up once (``tfloc/rosters.toml``) and may extend it; a module
joins one by declaring it (``"rosters"`` in its ``REGISTRY``)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from tfloc.errors import ConfigError
from tfloc.harness.config import load_config, parse_matchers
from tfloc.harness.rosters import JOINERS, ROSTERS_FILE, expand, joiners, rosters


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


def _file() -> dict[str, list[str]]:
    return tomllib.loads(ROSTERS_FILE.read_text(encoding="utf-8"))


def test_the_rosters_are_their_listed_names_with_the_declared_joiners_in_place() -> None:
    """Every roster is what the file lists, in order, with the matchers that join it by
    declaration in place of "..." (else after the listed names): without them, exactly the
    listed names, as before any module could join one."""
    for name, names in _file().items():
        got, joined = list(rosters()[name]), joiners(name)
        assert [m for m in got if m not in joined] == [m for m in names if m != JOINERS], name
        at = names.index(JOINERS) if JOINERS in names else len(names)
        assert got[at:at + len(joined)] == joined == sorted(joined), name
    assert _file()["trackers"][-2:] == [JOINERS, "odometry"]  # dead reckoning stays the floor


def test_a_module_joins_a_roster_by_declaring_it(monkeypatch: pytest.MonkeyPatch) -> None:
    from tfloc.core.registry import Declaration, declarations
    from tfloc.harness import rosters as module

    def joining(name: str, *to: str) -> Declaration:
        return Declaration(name, "m", "C", "s", "d.md", to, (), f"baselines/{name}.py")

    extra = (joining("zz-track", "trackers"), joining("aa-track", "trackers", "single-scan"),
             joining("odometry", "trackers"))  # listed already: stays where it is
    monkeypatch.setattr(module, "declarations", lambda: (*declarations(), *extra))
    rosters.cache_clear()
    try:
        listed = [m for m in _file()["trackers"] if m != JOINERS]
        assert rosters()["trackers"] == (*listed[:-1], "aa-track", "zz-track", "odometry")
        assert rosters()["single-scan"] == (*_file()["single-scan"], "aa-track")
        monkeypatch.setattr(module, "declarations", lambda: (joining("x-track", "trackerz"),))
        rosters.cache_clear()
        says = r"baselines/x-track.py: matcher 'x-track' joins roster 'trackerz'"
        with pytest.raises(ConfigError, match=says):
            rosters()
    finally:
        rosters.cache_clear()
