"""A reference scan as a map: its points joined into polylines (for scan-to-scan matching)."""

from __future__ import annotations

import numpy as np
import shapely

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose

from .vector import VectorMap


def polyline_map_from_scan(ranges: np.ndarray, laser: LaserSpec, pose: Pose | None = None,
                           max_gap: float = 0.5, max_gap_ratio: float = 0.15,
                           margin: float = 1.0) -> VectorMap:
    """Join consecutive returns of a scan into wall segments, seen from ``pose`` (default: the origin; metres).

    Neighbouring beams are joined unless one has no return or the points are farther apart
    than ``max_gap`` metres plus ``max_gap_ratio`` × range (a depth discontinuity, not a wall).
    The map's area is the convex hull of the returns and the sensor, grown by ``margin`` metres.
    """
    pose = Pose() if pose is None else pose
    pts = pose.transform(laser.to_points(ranges, keep_invalid=True))
    r = np.asarray(ranges, dtype=float)
    ok = laser.valid(r)
    a, b = pts[:-1], pts[1:]
    gap = np.hypot(*(b - a).T)
    with np.errstate(invalid="ignore"):
        join = ok[:-1] & ok[1:] & (gap <= max_gap + max_gap_ratio * np.fmin(r[:-1], r[1:]))
    # The mapped area (for in_bounds / is_free, never reflecting): the hull of the returns and of
    # the sensor itself, grown by ``margin``. Without the sensor, a robot standing outside its own
    # scan's hull (a scan of one wall) would be "outside the map" at its true pose.
    hull = shapely.convex_hull(shapely.multipoints(np.vstack((pts[ok], pose.xy[None]))))
    return VectorMap.from_segments(np.hstack((a[join], b[join])), name="scan",
                                   region=hull.buffer(margin))
