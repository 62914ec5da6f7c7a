"""Shared fixtures: the bundled test map and the paper's laser."""

from __future__ import annotations

from pathlib import Path

import pytest

import tfloc

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def test_room() -> tfloc.VectorMap:
    return tfloc.load_map(ROOT / "data" / "maps" / "test-room.geojson")


@pytest.fixture(scope="session")
def lms200() -> tfloc.LaserSpec:
    return tfloc.LaserSpec.lms200()
