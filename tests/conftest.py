"""Shared fixtures: the bundled test map and the paper's laser."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import tfloc

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def test_room() -> tfloc.VectorMap:
    return tfloc.load_map(ROOT / "data" / "maps" / "test-room.geojson")


@pytest.fixture
def office_maps(tmp_path) -> Path:
    """A fresh data folder holding the bundled office maps (``maps/office-{1,2,3}.geojson``),
    for the generators whose output is compared with the bundled datasets."""
    (tmp_path / "maps").mkdir()
    for lv in (1, 2, 3):
        shutil.copy(ROOT / "data" / "maps" / f"office-{lv}.geojson", tmp_path / "maps")
    return tmp_path


@pytest.fixture(scope="session")
def lms200() -> tfloc.LaserSpec:
    return tfloc.LaserSpec.lms200()


@pytest.fixture(scope="module")
def map_yaml(tmp_path_factory) -> Path:
    """The test room as a ROS map (YAML + PGM), for the bag tests."""
    from _rosbag_cases import room_grid

    from tfloc.io.rosmap import write_ros_map

    return write_ros_map(room_grid(), tmp_path_factory.mktemp("maps") / "room.yaml")


def pytest_collection_modifyitems(config, items) -> None:
    """Tests marked ``slow`` run only when asked for (``-m slow``, e.g. ``make chaos``)."""
    if "slow" in (config.getoption("-m") or ""):
        return
    skip = pytest.mark.skip(reason="slow: run with -m slow (make chaos)")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
