"""The configuration of ``cartographer`` (the pure-localization loop): Cartographer's own names and
shipped values, each from the file named beside it (cartographer ``configuration_files/``
``trajectory_builder_2d.lua`` = TB, ``pose_graph.lua`` = PG; cartographer_ros
``configuration_files/backpack_2d_localization.lua`` = LOC; the table with every source:
``docs/baselines/cartographer.md``). Metres, seconds; degrees where the name says so.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`~.tracker.CartographerTracker` (module notes)."""

    RULES: ClassVar[dict] = {
        "> 0": ("voxel_filter_size", "adaptive_max_length", "resolution", "missing_data_ray_length",
                "occupied_space_weight", "translation_weight", "rotation_weight", "max_constraint_distance",
                "fast_linear_search_window", "fast_angular_search_window_deg", "frozen_submap_size",
                "constraint_occupied_space_weight", "huber_scale", "max_range", "adaptive_max_range"),
        ">= 0": ("min_range", "adaptive_min_num_points", "linear_search_window",
                 "angular_search_window_deg", "translation_delta_cost_weight", "rotation_delta_cost_weight",
                 "motion_filter_max_time_seconds", "motion_filter_max_distance_meters",
                 "motion_filter_max_angle_deg", "constraint_translation_weight", "constraint_rotation_weight",
                 "loop_closure_translation_weight", "loop_closure_rotation_weight", "matcher_translation_weight",
                 "matcher_rotation_weight", "local_slam_pose_translation_weight", "local_slam_pose_rotation_weight",
                 "odometry_translation_weight", "odometry_rotation_weight",
                 "global_constraint_search_after_n_seconds", "optimize_every_n_nodes"),
        ">= 1": ("max_num_iterations", "num_range_data", "constraint_max_num_iterations",
                 "optimization_max_num_iterations", "max_submaps_to_keep",
                 "branch_and_bound_depth"),
        "(0, 1)": ("hit_probability", "miss_probability"),
        "[0, 1]": ("sampling_ratio", "min_score", "global_localization_min_score", "global_sampling_ratio"),
    }

    # -- local SLAM (TB) ------------------------------------------------------------------------
    min_range: float = 0.0  #: TB min_range (m)
    max_range: float = 30.0  #: TB max_range: farther returns become misses (m)
    missing_data_ray_length: float = 5.0  #: TB missing_data_ray_length (m)
    voxel_filter_size: float = 0.025  #: TB voxel_filter_size (m)
    adaptive_max_length: float = 0.5  #: TB adaptive_voxel_filter.max_length (m)
    adaptive_min_num_points: int = 200  #: TB adaptive_voxel_filter.min_num_points
    adaptive_max_range: float = 50.0  #: TB adaptive_voxel_filter.max_range (m)
    use_online_correlative_scan_matching: bool = True  #: the 2D laser + wheel odometry setting (docs)
    linear_search_window: float = 0.1  #: TB real_time_correlative_scan_matcher.linear_search_window (m)
    angular_search_window_deg: float = 20.0  #: TB real_time_correlative_scan_matcher.angular_search_window
    translation_delta_cost_weight: float = 0.1  #: TB real_time_correlative_scan_matcher
    rotation_delta_cost_weight: float = 0.1  #: TB real_time_correlative_scan_matcher
    occupied_space_weight: float = 1.0  #: TB ceres_scan_matcher.occupied_space_weight
    translation_weight: float = 10.0  #: TB ceres_scan_matcher.translation_weight
    rotation_weight: float = 40.0  #: TB ceres_scan_matcher.rotation_weight
    max_num_iterations: int = 20  #: TB ceres_scan_matcher.ceres_solver_options.max_num_iterations
    motion_filter_max_time_seconds: float = 5.0  #: TB motion_filter.max_time_seconds
    motion_filter_max_distance_meters: float = 0.2  #: TB motion_filter.max_distance_meters
    motion_filter_max_angle_deg: float = 1.0  #: TB motion_filter.max_angle_radians (math.rad(1.))
    num_range_data: int = 90  #: TB submaps.num_range_data
    resolution: float = 0.05  #: TB submaps.grid_options_2d.resolution (m)
    insert_free_space: bool = True  #: TB range_data_inserter ... insert_free_space
    hit_probability: float = 0.55  #: TB ... probability_grid_range_data_inserter.hit_probability
    miss_probability: float = 0.49  #: TB ... probability_grid_range_data_inserter.miss_probability
    # -- pose graph (PG, LOC) ---------------------------------------------------------------------
    optimize_every_n_nodes: int = 20  #: LOC POSE_GRAPH.optimize_every_n_nodes (PG: 90); 0 = never
    max_submaps_to_keep: int = 3  #: LOC / tuning guide: pure_localization_trimmer.max_submaps_to_keep
    sampling_ratio: float = 0.3  #: PG constraint_builder.sampling_ratio
    max_constraint_distance: float = 15.0  #: PG constraint_builder.max_constraint_distance (m)
    min_score: float = 0.55  #: PG constraint_builder.min_score
    global_localization_min_score: float = 0.6  #: PG constraint_builder.global_localization_min_score
    loop_closure_translation_weight: float = 1.1e4  #: PG constraint_builder.loop_closure_translation_weight
    loop_closure_rotation_weight: float = 1e5  #: PG constraint_builder.loop_closure_rotation_weight
    fast_linear_search_window: float = 7.0  #: PG fast_correlative_scan_matcher.linear_search_window (m)
    fast_angular_search_window_deg: float = 30.0  #: PG fast_correlative_scan_matcher.angular_search_window
    branch_and_bound_depth: int = 7  #: PG fast_correlative_scan_matcher.branch_and_bound_depth
    constraint_occupied_space_weight: float = 20.0  #: PG constraint_builder.ceres_scan_matcher
    constraint_translation_weight: float = 10.0  #: PG constraint_builder.ceres_scan_matcher
    constraint_rotation_weight: float = 1.0  #: PG constraint_builder.ceres_scan_matcher
    constraint_max_num_iterations: int = 10  #: PG constraint_builder.ceres_scan_matcher max_num_iterations
    matcher_translation_weight: float = 5e2  #: PG matcher_translation_weight (intra-submap)
    matcher_rotation_weight: float = 1.6e3  #: PG matcher_rotation_weight (intra-submap)
    huber_scale: float = 10.0  #: PG optimization_problem.huber_scale
    local_slam_pose_translation_weight: float = 1e5  #: PG optimization_problem
    local_slam_pose_rotation_weight: float = 1e5  #: PG optimization_problem
    odometry_translation_weight: float = 1e5  #: PG optimization_problem
    odometry_rotation_weight: float = 1e5  #: PG optimization_problem
    optimization_max_num_iterations: int = 50  #: PG optimization_problem.ceres_solver_options
    global_sampling_ratio: float = 0.003  #: PG global_sampling_ratio
    global_constraint_search_after_n_seconds: float = 10.0  #: PG global_constraint_search_after_n_seconds (s)
    # -- this port's reading (docs) -----------------------------------------------------------------
    frozen_submap_size: float = 20.0  #: side of a frozen submap tiled from the map (m)
    start_connected: bool = False  #: sensitivity only: the start pose counts as a connection to the map
