"""A reference scan as a map: its segments reflect, its area contains the sensor and a margin."""

import numpy as np
from shapely.geometry import LineString

from tfloc import LaserSpec, Pose, VectorMap
from tfloc.maps.scanmap import polyline_map_from_scan


def test_scan_of_one_wall_keeps_the_sensor_in_bounds():
    laser = LaserSpec.lms200()
    wall = VectorMap(walls=(LineString([(2, -3), (2, 3)]),))
    ranges = wall.raycast(Pose(0, 0, 0), laser)
    m = polyline_map_from_scan(ranges, laser)
    assert m.in_bounds(np.array([[0.0, 0.0], [-0.9, 0.0]])).all()      # sensor and 0.9 m behind it
    assert not m.in_bounds(np.array([[-1.5, 0.0]]))[0]
    # the region does not reflect: the virtual scan equals the real one
    assert np.allclose(m.raycast(Pose(0, 0, 0), laser), ranges, equal_nan=True)


def test_depth_jumps_are_not_joined():
    laser = LaserSpec.lms200()
    r = np.full(laser.n_beams, np.inf)
    r[80:90], r[90:100] = 2.0, 6.0
    m = polyline_map_from_scan(r, laser)
    assert len(m.segments) == 9 + 9
