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


def test_one_angle_is_wrapped_as_an_array_of_them_bit_for_bit():
    rng = np.random.default_rng(5)
    edges = [math.pi, -math.pi, 0.0, -0.0, 2 * math.pi, -3 * math.pi, 1e-320, -1e300,
             math.inf, -math.inf, math.nan, np.nextafter(math.pi, 4.0), np.nextafter(-math.pi, -4.0)]
    values = np.concatenate((rng.normal(0.0, 4.0, 20000), rng.uniform(-1e6, 1e6, 2000), edges))
    with np.errstate(invalid="ignore"):
        arrays = wrap_angle(values)
    scalars = np.array([wrap_angle(float(v)) for v in values])
    assert all(type(wrap_angle(v)) is float for v in (1.0, np.float64(1.0), 7))
    assert scalars.tobytes() == arrays.tobytes()


def test_wrap_angle_examples():
    assert wrap_angle(3 * math.pi / 2) == -math.pi / 2
    assert abs(angdiff(math.radians(179), math.radians(-179)) - math.radians(-2)) < 1e-12
