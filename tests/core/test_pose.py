"""SE(2) algebra: property tests."""

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from tfloc.core.pose import Pose, angdiff, wrap_angle

coord = st.floats(-50, 50, allow_nan=False)
angle = st.floats(-10, 10, allow_nan=False)
poses = st.builds(Pose, coord, coord, angle)


def close(a: Pose, b: Pose, tol: float = 1e-9) -> bool:
    return abs(a.x - b.x) < tol and abs(a.y - b.y) < tol and abs(angdiff(a.theta, b.theta)) < tol


@given(poses)
def test_inverse_composes_to_identity(p):
    assert close(p.compose(p.inverse()), Pose())
    assert close(p.inverse().compose(p), Pose())


@given(poses, poses, poses)
def test_compose_is_associative(a, b, c):
    assert close(a.compose(b).compose(c), a.compose(b.compose(c)), 1e-7)


@given(poses, poses)
def test_between_recovers_the_relative_pose(a, b):
    assert close(a.compose(a.between(b)), b, 1e-8)


@given(poses, st.lists(st.tuples(coord, coord), min_size=1, max_size=5))
def test_transform_matches_compose(p, pts):
    pts = np.array(pts)
    got = p.transform(pts)
    want = np.array([[q.x, q.y] for q in (p.compose(Pose(x, y, 0)) for x, y in pts)])
    assert np.allclose(got, want, atol=1e-9)


@given(angle, angle)
def test_angdiff_is_wrapped_and_consistent(a, b):
    d = angdiff(a, b)
    assert -math.pi <= d <= math.pi
    assert abs(math.sin(d) - math.sin(a - b)) < 1e-9 and abs(math.cos(d) - math.cos(a - b)) < 1e-9


def test_wrap_angle_examples():
    assert wrap_angle(3 * math.pi / 2) == -math.pi / 2
    assert abs(angdiff(math.radians(179), math.radians(-179)) - math.radians(-2)) < 1e-12
