"""ShortStraw (Algorithms 1-3) against analytic cases."""

import math

import numpy as np
import pytest
from _tf_oracles import is_line, merge_lines, straws
from shapely.geometry import box

from tfloc import LaserSpec, Pose, VectorMap
from tfloc.paper.corners import corner_candidates, resample, shortstraw


def test_resample_is_equidistant_and_keeps_endpoints():
    pts = np.array([[0, 0], [1.0, 0], [1.0, 1.0], [3.0, 1.0]])
    res = resample(pts, 0.25)
    steps = np.hypot(*np.diff(res, axis=0).T)
    assert np.allclose(steps, 0.25)
    assert np.allclose(res[0], pts[0])
    assert np.hypot(*(res[-1] - pts[-1])) <= 0.125        # ends within S/2 of the last point


def test_resample_uses_euclidean_distance_not_squared():
    # Alg. 1's literal D = |P1P2|^2 would put the first step at 0.5/2 = 0.25 m, not S = 0.5 m.
    res = resample(np.array([[0, 0], [2.0, 0]]), 0.5)
    assert np.allclose(res[1], [0.5, 0.0])


def test_straws_are_squared_chords():
    pts = np.array([[0, 0], [1, 0], [2, 0], [2, 1]], float)
    assert np.allclose(straws(pts, 1), [4.0, 2.0])


def test_is_line():
    pts = np.column_stack((np.linspace(0, 5, 21), np.zeros(21)))
    assert is_line(pts, 0, 20)
    bent = np.vstack((pts[:11], np.column_stack((np.full(10, 2.5), np.linspace(0.25, 2.5, 10)))))
    assert not is_line(bent, 0, 20)


def room_scan() -> np.ndarray:
    """A 360° scan from inside a 4 x 3 m room, as ordered points in the world frame."""
    laser = LaserSpec(10.0, math.radians(359.5), math.radians(0.5), math.radians(-170))
    pose = Pose(1.5, 1.2, 0.0)
    r = VectorMap(outline=box(0, 0, 4, 3)).raycast(pose, laser)
    return pose.transform(laser.to_points(r))


def test_finds_the_four_corners_of_a_rectangular_room():
    corners = shortstraw(room_scan(), spacing=0.2)
    inner = corners[1:-1]                       # the first and last points are always kept
    truth = np.array([[0, 0], [4, 0], [4, 3], [0, 3]], float)
    d = np.hypot(*(inner[:, None, :] - truth[None]).transpose(2, 0, 1))
    assert len(inner) == 4
    assert d.min(axis=0).max() < 0.2           # each room corner found within S
    assert d.min(axis=1).max() < 0.2           # and nothing else


@pytest.mark.parametrize("noise", [0.0, 0.005])
def test_no_corner_on_a_straight_wall(noise):
    rng = np.random.default_rng(0)
    x = np.linspace(0, 6, 120)
    pts = np.column_stack((x, 2.0 + rng.normal(0, noise, x.size)))
    corners = shortstraw(pts, spacing=0.3)
    assert len(corners) == 2                    # only the two ends


def test_candidates_include_both_ends_and_merge_keeps_them():
    res = resample(room_scan(), 0.2)
    cand = corner_candidates(res)
    assert cand[0] == 0 and cand[-1] == len(res) - 1
    kept = merge_lines(res, cand.astype(np.int64))
    assert kept[0] == 0 and kept[-1] == len(res) - 1 and len(kept) <= len(cand)
