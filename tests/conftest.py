"""Shared fixtures: the bundled test map and the paper's laser."""

from __future__ import annotations

import multiprocessing
import shutil
from pathlib import Path

import pytest

import tfloc

ROOT = Path(__file__).resolve().parents[1]


class _ForkserverWorkers:
    """``multiprocessing`` as the local runner sees it in this test process, but for the start
    method: its pool's workers come from a forkserver that has imported tfloc's task code (and
    the toy matchers) once, instead of each spawned worker importing numpy, scipy, pandas and
    numba anew (2-3 s of CPU each, paid by every in-process ``run``). A forkserver's worker is a
    fresh process like a spawned one: no state of this process, tasks pickled, the pool's
    initializer run. The commands the tests start (``tfloc bench`` in a subprocess) spawn their
    workers exactly as a user's run does."""

    def __init__(self) -> None:
        self._ctx = multiprocessing.get_context("forkserver")
        self._ctx.set_forkserver_preload(["tfloc.harness.task", "toy_matchers"])

    def get_context(self, method: str | None = None):
        return self._ctx

    def __getattr__(self, name: str):
        return getattr(multiprocessing, name)


@pytest.fixture(autouse=True, scope="session")
def _workers_from_a_forkserver():
    from tfloc.harness import runner

    mp = pytest.MonkeyPatch()
    mp.setattr(runner, "multiprocessing", _ForkserverWorkers())
    yield
    mp.undo()


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


#: markers whose tests run only when ``-m`` names them: ``slow`` (``make chaos``, ``make fuzz``)
#: and ``sweep`` (the longer members of a parametrised check and full rebuilds, ``make test-sweeps``,
#: which ``make bench`` runs)
ON_REQUEST = {"slow": "slow: run with -m slow (make chaos)",
              "sweep": "sweep: run with -m sweep (make test-sweeps, part of make bench)"}


def pytest_collection_modifyitems(config, items) -> None:
    """Tests marked ``slow`` or ``sweep`` run only when ``-m`` asks for them."""
    asked = config.getoption("-m") or ""
    for marker, reason in ON_REQUEST.items():
        if marker in asked:
            continue
        skip = pytest.mark.skip(reason=reason)
        for item in items:
            if marker in item.keywords:
                item.add_marker(skip)
