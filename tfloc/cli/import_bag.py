"""Make a scenario dataset from a ROS 1 or ROS 2 bag (sqlite3 or mcap); no ROS installation needed.

The scans come from a sensor_msgs/LaserScan topic; the reference poses (PoseStamped,
PoseWithCovarianceStamped, Odometry, or a tf frame pair) are interpolated to the scan stamps,
and scans outside the pose stream are skipped and counted. The map is a map_server YAML
(--map) or an OccupancyGrid topic in the bag (--map-topic); it is stored in the dataset.
Initial poses are the reference perturbed in the paper's 3 x 3 offset bins (--seed), or come
from a second pose topic (--initial-topic, e.g. AMCL's estimate or odometry with --align-initial).
With --odom-topic (nav_msgs/Odometry, or a tf topic with --odom-frames odom base_link) the
dataset is a sequence for `tfloc track`: the scans in time order with the odometry at each, the
robot starting at the reference pose of the first scan.

Example:
  tfloc import-bag run1.bag --scan-topic /scan --pose-topic /ground_truth \\
      --map map.yaml --out data/scenarios/run1
  tfloc import-bag run1.bag --scan-topic /scan --pose-topic /ground_truth --odom-topic /odom \\
      --map map.yaml --out data/scenarios/run1-sequence
"""

from __future__ import annotations

import argparse
from pathlib import Path

from tfloc.core.pose import Pose

HELP = "make a scenario dataset from a ROS 1/ROS 2 bag (LaserScan + reference poses + map)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("bag", type=Path, help="ROS 1 .bag file, or ROS 2 bag directory / .db3 / .mcap file")
    p.add_argument("--scan-topic", required=True, help="sensor_msgs/LaserScan topic")
    p.add_argument("--pose-topic", required=True,
                   help="reference poses: PoseStamped, PoseWithCovarianceStamped, Odometry or tf topic")
    p.add_argument("--pose-frames", nargs=2, metavar=("PARENT", "CHILD"),
                   help="frame pair when --pose-topic is a tf topic (e.g. map base_link)")
    m = p.add_mutually_exclusive_group(required=True)
    m.add_argument("--map", type=Path, help="map_server YAML (+ its image), copied into the dataset")
    m.add_argument("--map-topic", help="nav_msgs/OccupancyGrid topic in the bag (the last message)")
    p.add_argument("--out", type=Path, required=True, help="dataset directory to create")
    p.add_argument("--name", default="", help="dataset name (default: the --out directory's name)")
    p.add_argument("--initial-topic", help="take initial poses from this pose topic instead of perturbing")
    p.add_argument("--initial-frames", nargs=2, metavar=("PARENT", "CHILD"),
                   help="frame pair when --initial-topic is a tf topic")
    p.add_argument("--align-initial", action="store_true",
                   help="the initial topic is in another frame (odometry): align it to the reference "
                        "at the first imported scan")
    p.add_argument("--seed", type=int, default=None, help="seed of the initial-pose perturbation")
    p.add_argument("--clearance", type=float, default=0.2,
                   help="perturbed initial positions keep this distance (m) from occupied cells")
    p.add_argument("--every", type=int, default=1, help="keep every N-th scan message (default 1)")
    p.add_argument("--limit", type=int, default=0, help="import at most N scans (default: all)")
    p.add_argument("--max-pose-gap", type=float, default=1.0,
                   help="a scan between two poses further apart than this (s) is skipped (default 1)")
    p.add_argument("--laser-offset", nargs=3, type=float, default=(0.0, 0.0, 0.0),
                   metavar=("X", "Y", "YAW"),
                   help="laser pose in the frame of the reference poses (m, m, rad; default 0 0 0)")
    p.add_argument("--odom-topic",
                   help="write a sequence (tracking): the robot's odometry, nav_msgs/Odometry or a tf topic")
    p.add_argument("--odom-frames", nargs=2, metavar=("PARENT", "CHILD"),
                   help="frame pair when --odom-topic is a tf topic (e.g. odom base_link)")


def run(args: argparse.Namespace) -> int:
    from tfloc.datasets.from_bag import BagImport, import_bag

    cfg = BagImport(args.bag, args.scan_topic, args.pose_topic, args.out, args.map, args.map_topic,
                    args.name, tuple(args.pose_frames) if args.pose_frames else None,
                    args.initial_topic, tuple(args.initial_frames) if args.initial_frames else None,
                    args.align_initial, args.seed, args.clearance, args.every, args.limit,
                    args.max_pose_gap, Pose(*args.laser_offset), args.odom_topic,
                    tuple(args.odom_frames) if args.odom_frames else None)
    s = import_bag(cfg)
    skipped = s.outside_poses + s.outside_initial + s.no_return + s.outside_odom
    print(f"{s.path}: {s.kept} scans from {s.messages} messages on {args.scan_topic}"
          + (f"; skipped {s.outside_poses} outside {args.pose_topic}" if s.outside_poses else "")
          + (f", {s.outside_initial} outside {args.initial_topic}" if s.outside_initial else "")
          + (f", {s.outside_odom} outside {args.odom_topic} or out of time order" if s.outside_odom else "")
          + (f", {s.no_return} without a return" if s.no_return else "")
          + ("" if skipped else "; none skipped"))
    return 0
