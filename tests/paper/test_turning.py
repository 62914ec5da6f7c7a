"""Algorithm 4 and Sec. 4.3 against analytic cases."""

import math

import numpy as np
import pytest

from tfloc.paper.turning import match, turning_function


def rotate(p: np.ndarray, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return p @ np.array([[c, s], [-s, c]])


def test_square_is_a_staircase_of_right_angles():
    tf = turning_function(np.array([[0, 0], [2, 0], [2, 2], [0, 2]], float))
    assert np.allclose(tf.breaks, [0, 0.25, 0.5, 0.75, 1.0])
    assert np.allclose(tf.angles, [0, math.pi / 2, math.pi, 3 * math.pi / 2])


def test_clockwise_turns_are_negative():
    tf = turning_function(np.array([[0, 0], [0, 2], [2, 2], [2, 0]], float))
    assert np.allclose(np.diff(tf.angles), -math.pi / 2)


def test_scale_invariance():
    p = np.array([[0, 0], [3, 0], [3, 1], [2, 2], [0, 1.5]])
    a, b = turning_function(p), turning_function(5.0 * p)
    assert np.allclose(a.breaks, b.breaks) and np.allclose(a.angles, b.angles)


POLY = np.array([[0, 0], [3, 0], [3, 1], [2, 2], [1.2, 1.1], [0, 1.5]], float)


@pytest.mark.parametrize("shift", range(len(POLY)))
@pytest.mark.parametrize("angle", [0.0, 0.3, -1.2, 3.0])
def test_shifted_rotated_copy_matches_exactly(shift, angle):
    real = turning_function(np.roll(rotate(POLY, angle), shift, axis=0))
    m = match(real, turning_function(POLY))
    assert m.distance == pytest.approx(0.0, abs=1e-6)
    assert math.remainder(m.rotation - angle, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_different_shapes_have_positive_distance():
    square = turning_function(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float))
    assert match(square, turning_function(POLY)).distance > 0.1


def test_degenerate_polygon_is_rejected():
    with pytest.raises(ValueError):
        turning_function(np.array([[0, 0], [1, 0]], float))
