"""Baseline ``gicp``: bad parameters."""

from __future__ import annotations

import numpy as np
import pytest

import tfloc

pytest.importorskip("small_gicp")
from tfloc.baselines.gicp import GicpMatcher, stack_layers  # noqa: E402


def test_layers_stack_the_plane() -> None:
    pts = np.array([[1.0, 2.0], [3.0, 4.0]])
    out = stack_layers(pts, (-0.05, 0.0, 0.05))
    assert out.shape == (6, 3)
    assert np.allclose(out[:, :2], np.tile(pts, (3, 1)))
    assert np.allclose(out[:, 2], [-0.05, -0.05, 0.0, 0.0, 0.05, 0.05])


def test_registered_name_and_bad_parameters() -> None:
    matcher = tfloc.get_matcher("gicp")
    assert isinstance(matcher, GicpMatcher) and matcher.name == "gicp"
    for bad in ({"no_such_option": 1}, {"registration_type": "VGICP"}, {"gates": [0.5, 0.0]},
                {"layers": []}, {"map_spacing": -0.05}):
        with pytest.raises(tfloc.MatcherError, match="gicp"):
            tfloc.get_matcher("gicp", **bad)
