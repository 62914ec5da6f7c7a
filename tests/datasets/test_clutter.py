"""The changed-world generator: unmapped objects occlude the requested share of beams, seeded."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.datasets.clutter import ClutterSpec, occlude, occluded_share
from tfloc.datasets.offices import office_furnished


@pytest.fixture(scope="module")
def office():
    return office_furnished()


POSES = [Pose(2.0, 7.5, 0.0), Pose(10.0, 3.0, 1.2), Pose(17.0, 12.0, -2.0), Pose(6.5, 10.5, 2.5)]


@pytest.mark.parametrize("share", [0.10, 0.25])
def test_objects_occlude_the_requested_share(office, share: float) -> None:
    laser = LaserSpec.lms200()
    spec = ClutterSpec(share)
    rng = np.random.default_rng(7)
    for pose in POSES:
        clean = office.raycast(pose, laser)
        ranges, objects = occlude(office, pose, laser, spec, rng)
        got = occluded_share(clean, ranges)
        assert abs(got - share) <= spec.tolerance + 1e-9, (pose, got)
        assert objects and (ranges <= clean).all()
        for obj in objects:  # unmapped objects stand in free space, away from the laser
            assert office.is_free(np.array(obj.exterior.coords)).all()
            assert obj.distance(shapely.Point(pose.x, pose.y)) >= spec.min_dist_m - 0.25


def test_seeded_and_zero_share_draws_nothing(office) -> None:
    laser, pose = LaserSpec.lms200(), POSES[1]
    a = occlude(office, pose, laser, ClutterSpec(0.25), np.random.default_rng(3))[0]
    b = occlude(office, pose, laser, ClutterSpec(0.25), np.random.default_rng(3))[0]
    c = occlude(office, pose, laser, ClutterSpec(0.25), np.random.default_rng(4))[0]
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    rng = np.random.default_rng(5)
    state = rng.bit_generator.state
    r, objs = occlude(office, pose, laser, ClutterSpec(0.0), rng)
    assert objs == [] and rng.bit_generator.state == state
    np.testing.assert_array_equal(r, office.raycast(pose, laser))
