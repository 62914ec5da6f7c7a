"""Make a scenario dataset from a ROS 1 or ROS 2 bag (sqlite3 or mcap); no ROS installation needed.

The scans come from a sensor_msgs/LaserScan topic; the reference poses (PoseStamped,
PoseWithCovarianceStamped, Odometry, or a tf frame pair) are interpolated to the scan stamps,
and scans outside the pose stream are skipped and counted. The map is a map_server YAML
(--map) or an OccupancyGrid topic in the bag (--map-topic); it is stored in the dataset.
Initial poses are the reference perturbed in the paper's 3 x 3 offset bins (--seed), or come
from a second pose topic (--initial-topic, e.g. AMCL's estimate or odometry with --align-initial).
With --odom-topic (nav_msgs/Odometry, or a tf topic with --odom-frames odom base_link) the
dataset is a sequence for `tfloc track`: the scans in time order with the odometry at each, the
robot starting at the reference pose of the first scan. Without --pose-topic (no truth: what a
robot owner has) the sequence's true poses are empty and the robot starts at --initial-pose, at
--initial-topic's pose at the first scan (e.g. AMCL's /amcl_pose), or where a global matcher
(--initial-matcher, default tf-global) finds it on the first scans. The import prints the
recording checks' flags (odometry stalls and jumps, scan gaps: `tfloc check-recording`).

Example:
  tfloc import-bag run1.bag --scan-topic /scan --pose-topic /ground_truth \\
      --map map.yaml --out data/scenarios/run1
  tfloc import-bag run1.bag --scan-topic /scan --pose-topic /ground_truth --odom-topic /odom \\
      --map map.yaml --out data/scenarios/run1-sequence
  tfloc import-bag run1.bag --scan-topic /scan --odom-topic /odom --map map.yaml \\
      --out data/scenarios/run1-mine
"""

from __future__ import annotations

import argparse
from pathlib import Path

from tfloc.core.pose import Pose

HELP = "make a scenario dataset from a ROS 1/ROS 2 bag (LaserScan + reference poses or odometry + map)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("bag", type=Path, help="ROS 1 .bag file, or ROS 2 bag directory / .db3 / .mcap file")
    p.add_argument("--scan-topic", required=True, help="sensor_msgs/LaserScan topic")
    p.add_argument("--pose-topic",
                   help="reference poses (truth): PoseStamped, PoseWithCovarianceStamped, Odometry or tf "
                        "topic; without it --odom-topic is needed and the sequence has no truth")
    p.add_argument("--pose-frames", nargs=2, metavar=("PARENT", "CHILD"),
                   help="frame pair when --pose-topic is a tf topic (e.g. map base_link)")
    m = p.add_mutually_exclusive_group(required=True)
    m.add_argument("--map", type=Path, help="map_server YAML (+ its image), copied into the dataset")
    m.add_argument("--map-topic", help="nav_msgs/OccupancyGrid topic in the bag (the last message)")
    p.add_argument("--out", type=Path, required=True, help="dataset directory to create")
    p.add_argument("--name", default="", help="dataset name (default: the --out directory's name)")
    p.add_argument("--initial-topic",
                   help="take initial poses from this pose topic instead of perturbing; without "
                        "--pose-topic: the sequence starts at its pose at the first scan it covers")
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
    p.add_argument("--initial-pose", nargs=3, type=float, metavar=("X", "Y", "YAW"),
                   help="without --pose-topic: the robot's pose at the first scan (m, m, rad; map frame)")
    p.add_argument("--initial-matcher", default="tf-global",
                   help="without --pose-topic, --initial-pose and --initial-topic: the global matcher "
                        "that finds the start on the first scans (default tf-global)")
    p.add_argument("--initial-scans", type=int, default=3,
                   help="scans the global matcher runs on (default 3; its answers are carried back "
                        "to the first scan by the odometry and scored on all of them)")


def run(args: argparse.Namespace) -> int:
    from tfloc.datasets.bag_files import gaps_text
    from tfloc.datasets.from_bag import BagImport, import_bag

    cfg = BagImport(args.bag, args.scan_topic, args.pose_topic, args.out, args.map, args.map_topic,
                    args.name, tuple(args.pose_frames) if args.pose_frames else None,
                    args.initial_topic, tuple(args.initial_frames) if args.initial_frames else None,
                    args.align_initial, args.seed, args.clearance, args.every, args.limit,
                    args.max_pose_gap, Pose(*args.laser_offset), args.odom_topic,
                    tuple(args.odom_frames) if args.odom_frames else None,
                    Pose(*args.initial_pose) if args.initial_pose else None, args.initial_matcher,
                    args.initial_scans)
    s = import_bag(cfg)
    skipped = s.outside_poses + s.outside_initial + s.no_return + s.outside_odom
    before = " before its first pose" if args.odom_topic and not args.pose_topic else ""
    print(f"{s.path}: {s.kept} scans from {s.messages} messages on {args.scan_topic}"
          + (f"; skipped {s.outside_poses} outside {args.pose_topic}" if s.outside_poses else "")
          + (f", {s.outside_initial} outside {args.initial_topic}{before}" if s.outside_initial else "")
          + (f", {s.outside_odom} outside {args.odom_topic} or out of time order" if s.outside_odom else "")
          + (f", {s.no_return} without a return" if s.no_return else "")
          + ("" if skipped else "; none skipped")
          + ("" if args.pose_topic else "; no truth (true_* empty)"))
    if s.start is not None:
        print(f"{s.path}: {s.start.text()}")
    if s.odometry_gaps:
        print(f"{s.path}: {gaps_text(s.odometry_gaps, args.odom_topic)} (skipped; in scenario.json's "
              "generator.odometry_gaps)")
    if args.odom_topic:
        from tfloc.evaluation.recording import check_recording
        from tfloc.io.scenario import read_scans, read_scenario

        sc = read_scenario(s.path)
        check = check_recording(read_scans(sc), sc.laser)
        print(f"{s.path}: recording checks: {check.summary()}")
        for line in check.lines(limit=5, more=f"tfloc check-recording {s.path}"):
            print(f"  {line}")
    return 0
