"""Cartographer's local SLAM (``LocalTrajectoryBuilder2D``, ``local_trajectory_builder_2d.cc``):
each scan matched against the trajectory's own submaps, then inserted into them.

Per scan, in Cartographer's order:

1. **Range data**: returns within [``min_range``, ``max_range``] are hits; farther ones become
   misses ``missing_data_ray_length`` along their beam (no-return beams are dropped, as
   cartographer_ros drops ranges outside the message's limits); both through the voxel filter
   (``voxel_filter_size``). The matchers read the hits through the adaptive voxel filter
   (:func:`._filters.matched_points`).
2. **Pose extrapolator**: with odometry at every scan and no IMU (``use_imu_data = false``) its
   prediction is the last matched pose composed with the odometry increment.
3. **Scan matching** against the older active submap (``active_submaps.front()``): the real-time
   correlative scan matcher when ``use_online_correlative_scan_matching`` (:mod:`._csm`), then the
   Ceres scan matcher (:mod:`._ceres`) towards the prediction. No submap yet: the prediction.
4. **Motion filter** (``motion_filter.cc``): the scan is inserted only if more than
   ``max_time_seconds`` passed, or the pose moved more than ``max_distance_meters`` or turned
   more than ``max_angle_radians`` since the last inserted scan (the first always is).
5. **Insertion** into the active submaps (:class:`._submaps.ActiveSubmaps`); an inserted scan is
   a node of the pose graph.

Poses are in the trajectory's local frame (the first scan at the origin); metres, radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tfloc.core.pose import Pose, wrap_angle

from . import _ceres, _csm
from ._filters import matched_points, voxel_filter
from ._submaps import ActiveSubmaps, Submap


@dataclass(frozen=True)
class Insertion:
    """A scan that became a node: its local pose, the submaps it went into (older first), whether
    it finished the older one, and its robot-frame returns through the adaptive voxel filter (the
    node's ``filtered_gravity_aligned_point_cloud``, which the constraint builder matches)."""

    pose: Pose
    submaps: tuple[Submap, ...]
    finished: bool
    points: np.ndarray


class LocalSlam:
    """Local SLAM of one trajectory (module notes); ``c`` is the tracker's configuration."""

    def __init__(self, c) -> None:  # noqa: ANN001 - tracker.Config (no import cycle)
        self.c = c
        self.active = ActiveSubmaps(c.num_range_data, c.resolution)
        self.pose = Pose(0.0, 0.0, 0.0)
        self._last: tuple[float, Pose] | None = None  # motion filter: last inserted (stamp, pose)

    def _range_data(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = self.c
        r = np.hypot(points[:, 0], points[:, 1])
        hits = points[(r >= c.min_range) & (r <= c.max_range)]
        far = points[r > c.max_range]
        misses = far * (c.missing_data_ray_length / np.hypot(far[:, 0], far[:, 1]))[:, None]
        return hits[voxel_filter(hits, c.voxel_filter_size)], misses[voxel_filter(misses, c.voxel_filter_size)]

    def _similar(self, stamp: float, pose: Pose) -> bool:
        """``MotionFilter::IsSimilar`` (module notes, step 4)."""
        c = self.c
        if self._last is None:
            return False
        t, p = self._last
        return (stamp - t <= c.motion_filter_max_time_seconds
                and math.hypot(pose.x - p.x, pose.y - p.y) <= c.motion_filter_max_distance_meters
                and abs(float(wrap_angle(pose.theta - p.theta))) <= math.radians(c.motion_filter_max_angle_deg))

    def step(self, points: np.ndarray, odom_delta: Pose, stamp: float) -> tuple[Pose, Insertion | None, dict]:
        """One scan (robot-frame returns ``(N, 2)``, metres): its local pose, the insertion if it
        became a node, and the matchers' figures."""
        c = self.c
        pred = self.pose.compose(odom_delta)
        returns = matched_points(points, min_range=c.min_range, max_range=c.max_range,
                                 voxel_size=c.voxel_filter_size, max_length=c.adaptive_max_length,
                                 min_num_points=c.adaptive_min_num_points, adaptive_max_range=c.adaptive_max_range)
        info: dict = {"points": int(len(returns))}
        pose = pred
        if len(returns) and self.active.submaps:
            grid = self.active.submaps[0].grid()
            start = pred
            if c.use_online_correlative_scan_matching:
                start, score, _ = _csm.match(grid, returns, pred, c.linear_search_window,
                                             math.radians(c.angular_search_window_deg),
                                             c.translation_delta_cost_weight, c.rotation_delta_cost_weight)
                info["csm_score"] = score
            pose, sol = _ceres.match(grid, returns, pred, start, c.occupied_space_weight, c.translation_weight,
                                     c.rotation_weight, c.max_num_iterations)
            info["local_cost"] = float(sol.cost)
        self.pose = pose
        if self._similar(stamp, pose):
            return pose, None, info
        self._last = (stamp, pose)
        hits, misses = self._range_data(points)
        submaps, finished = self.active.insert(np.array([pose.x, pose.y]), pose.transform(hits),
                                               pose.transform(misses), c.hit_probability, c.miss_probability,
                                               c.insert_free_space)
        return pose, Insertion(pose, tuple(submaps), finished, returns), info
