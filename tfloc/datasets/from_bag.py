"""A scenario dataset from a ROS bag: scans, reference poses at the scan stamps, a map, and
initial poses (perturbed in the paper's bins from a seed, or from a second pose topic); or, given
an odometry topic, a *sequence* (tracking, :mod:`tfloc.datasets.bag_sequence`): the scans in time
order with the robot's odometry pose at each, with reference poses or without (a robot owner's
recording: the start from ``--initial-pose``, ``--initial-topic`` or a global matcher)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tfloc.core.pose import Pose
from tfloc.errors import BagError, ConfigError, DatasetError
from tfloc.io.scenario import Scan, write_scenario

from .bag_files import ImportSummary, returning_rows, save_map, source_record, span
from .interpolate import interpolate_poses

if TYPE_CHECKING:
    from tfloc.io.rosbag import PoseStream


@dataclass(frozen=True)
class BagImport:
    """What to import from a bag, and how.

    Attributes:
        bag: a ROS 1 ``.bag`` file, or a ROS 2 bag directory / ``.db3`` / ``.mcap`` file.
        pose_topic: the reference poses (PoseStamped, PoseWithCovarianceStamped, Odometry or tf);
            None: no truth, a sequence (``odom_topic`` needed) whose ``true_*`` are empty.
        map_file: a map_server YAML (or GeoJSON) copied into the dataset, or
        map_topic: a ``nav_msgs/OccupancyGrid`` topic saved as ``map.yaml`` + ``map.pgm``.
        initial_topic: take initial poses from this pose topic instead of perturbing;
        initial_frames: its frame pair if it is a tf topic;
        align_initial: the initial topic is in another frame (e.g. odometry): align it to the
            reference at the first imported scan, so its drift is the initial error.
        seed, clearance_m: the perturbation (paper's 3 × 3 offset bins) when no initial topic.
        odom_topic: write a sequence dataset: the robot's odometry (nav_msgs/Odometry, a pose
            topic, or tf with ``odom_frames``, e.g. ``odom base_link``) interpolated to the scan
            stamps; excludes the perturbation, and with reference poses ``initial_topic`` (the
            start is the reference). ``odom_frames``: its frame pair if it is a tf topic.
        initial_pose: without reference poses, the robot's pose at the first scan (map frame);
            else ``initial_topic`` at the first scan it covers; else ``initial_matcher`` (a
            registered global matcher) run on the first ``initial_scans`` scans
            (:mod:`tfloc.datasets.first_pose`).
    """

    bag: Path
    scan_topic: str  #: a sensor_msgs/LaserScan topic
    pose_topic: str | None
    out: Path  #: the dataset directory to write
    map_file: Path | None = None
    map_topic: str | None = None
    name: str = ""  #: the dataset's name (default: the name of out)
    pose_frames: tuple[str, str] | None = None  #: (parent, child) if pose_topic is tf
    initial_topic: str | None = None
    initial_frames: tuple[str, str] | None = None
    align_initial: bool = False
    seed: int | None = None
    clearance_m: float = 0.2
    every: int = 1  #: keep every n-th scan message
    limit: int = 0  #: at most this many scans (0 = all)
    max_pose_gap_s: float = 1.0  #: a scan between poses further apart is not covered (s)
    laser_offset: Pose = field(default_factory=Pose)  #: laser pose, reference frame (m, rad)
    odom_topic: str | None = None
    odom_frames: tuple[str, str] | None = None
    initial_pose: Pose | None = None
    initial_matcher: str = "tf-global"
    initial_scans: int = 3

    def __post_init__(self) -> None:
        """Argument errors (one type, :class:`ConfigError`, whoever builds the import)."""
        if (self.map_file is None) == (self.map_topic is None):
            raise ConfigError("give the map either as a file (--map) or as an OccupancyGrid topic (--map-topic)")
        if self.every < 1 or self.limit < 0:
            raise ConfigError(f"--every must be ≥ 1 and --limit ≥ 0, got {self.every} and {self.limit}")
        if self.initial_frames and not self.initial_topic:
            raise ConfigError("--initial-frames needs --initial-topic")
        if self.align_initial and not self.initial_topic:
            raise ConfigError("--align-initial needs --initial-topic")
        if self.odom_frames and not self.odom_topic:
            raise ConfigError("--odom-frames needs --odom-topic")
        if not self.pose_topic and not self.odom_topic:
            raise ConfigError("a single-scan dataset needs reference poses (--pose-topic); without them give "
                              "--odom-topic for a sequence, which starts at --initial-pose X Y YAW, "
                              "--initial-topic or where --initial-matcher finds it")
        if self.odom_topic and self.pose_topic and (self.initial_topic or self.seed is not None
                                                    or self.initial_pose is not None):
            raise ConfigError("--odom-topic writes a sequence (the start is the reference at the first scan): "
                              "with --pose-topic it takes no --initial-topic, --initial-pose or --seed")
        if not self.pose_topic and (self.align_initial or self.seed is not None):
            raise ConfigError("--align-initial and --seed need reference poses (--pose-topic)")
        if self.initial_pose is not None and (self.pose_topic or self.initial_topic):
            raise ConfigError("--initial-pose is the start of a sequence without reference poses: it takes "
                              "no --pose-topic or --initial-topic")
        if self.initial_pose is not None and not self.initial_pose.is_finite():
            raise ConfigError(f"--initial-pose must be finite, got {self.initial_pose}")
        if self.initial_scans < 1:
            raise ConfigError(f"--initial-scans must be ≥ 1, got {self.initial_scans}")
        if not (self.clearance_m >= 0 and self.max_pose_gap_s > 0 and self.laser_offset.is_finite()):
            raise ConfigError(f"--clearance must be ≥ 0 m, --max-pose-gap > 0 s and --laser-offset finite, got "
                              f"{self.clearance_m}, {self.max_pose_gap_s} and {self.laser_offset}")


def import_bag(cfg: BagImport) -> ImportSummary:
    """Read the bag and write the dataset directory ``cfg.out``; returns the counts."""
    from tfloc.io.rosbag import Bag

    from .protocol import Perturbation, perturb

    out = Path(cfg.out)
    if (out / "scenario.json").exists() or (out / "scans.csv").exists():
        raise DatasetError(f"{out}: a dataset exists there already; choose another --out or remove it")
    with Bag(cfg.bag) as bag:
        scans = bag.scans(cfg.scan_topic)
        ref = bag.poses(cfg.pose_topic, cfg.pose_frames) if cfg.pose_topic else None
        init = bag.poses(cfg.initial_topic, cfg.initial_frames) if cfg.initial_topic else None
        odom = bag.poses(cfg.odom_topic, cfg.odom_frames) if cfg.odom_topic else None
        grid = bag.grid(cfg.map_topic) if cfg.map_topic else None

    pick = np.flatnonzero(scans.index % cfg.every == 0)
    t = scans.stamps[pick]
    if ref is None:
        truth, covered = np.full((t.size, 3), math.nan), np.ones(t.size, dtype=bool)
    else:
        truth, covered = interpolate_poses(ref.stamps, ref.poses, t, cfg.max_pose_gap_s)
    if not covered.any():
        raise BagError(f"{cfg.bag}: {cfg.pose_topic} covers none of the {t.size} scans on {cfg.scan_topic} "
                       f"(scan message {scans.index[pick[0]]} at t={t[0]:.3f} s; poses span "
                       f"{span(ref.stamps)}, max gap {cfg.max_pose_gap_s:g} s)")
    if odom is not None:
        from .bag_sequence import import_sequence

        return import_sequence(cfg, scans, pick, t, truth, covered, init, odom, grid, ref)
    keep = covered.copy()
    outside_init = 0
    if init is not None:
        start, outside_init, keep = _also_covered(cfg, init, cfg.initial_topic, t, keep)
    rows, no_return = returning_rows(cfg, scans, pick, keep)
    n_empty = int(np.count_nonzero(no_return))
    off = cfg.laser_offset
    true_p = np.array([Pose.from_array(truth[k]).compose(off).as_array() for k in rows])

    from tfloc.io.maps import load_map

    the_map = grid if grid is not None else load_map(cfg.map_file)
    if not the_map.in_bounds(true_p[:, :2]).any():
        raise BagError(f"{cfg.bag}: none of the {cfg.pose_topic} poses at the scans lies inside the map "
                       f"(bounds {tuple(round(b, 2) for b in the_map.bounds)} m); are they in the map frame?")
    if init is not None:
        ip = start[rows]
        if cfg.align_initial:  # express the initial stream in the reference frame at the first scan
            T = Pose.from_array(truth[rows[0]]).compose(Pose.from_array(ip[0]).inverse())
            ip = np.array([T.compose(Pose.from_array(p)).as_array() for p in ip])
        init_p = np.array([Pose.from_array(p).compose(off).as_array() for p in ip])
        groups = [cfg.initial_topic.strip("/").replace("/", "-")] * rows.size
        how = {"initial_topic": cfg.initial_topic, "align_initial": cfg.align_initial}
        init_text = f"initial poses from {cfg.initial_topic}" + (" (aligned at the first scan)"
                                                                  if cfg.align_initial else "")
    else:
        pcfg = Perturbation(clearance_m=cfg.clearance_m) if cfg.seed is None else \
            Perturbation(seed=cfg.seed, clearance_m=cfg.clearance_m)
        init_p, groups = perturb(true_p, the_map, pcfg)
        how = {"perturbation": {"seed": pcfg.seed, "clearance_m": pcfg.clearance_m,
                                "bins": "0-1/1-2/2-3 m x 0-5/5-10/10-15 deg, groups d{i}-a{j}"}}
        init_text = f"initial poses perturbed in the paper's 3x3 offset bins (seed {pcfg.seed})"
    rows_out = [Scan(f"s{scans.index[pick[k]]:05d}", g, scans.ranges[pick[k]], Pose.from_array(ip_),
                     Pose.from_array(tp), stamp=float(t[k]))
                for k, g, ip_, tp in zip(rows, groups, init_p, true_p, strict=True)]
    las = scans.laser
    out.mkdir(parents=True, exist_ok=True)
    map_path = save_map(cfg, grid, out)
    source = source_record(cfg, scans, ref, rows, {"how": how, "skipped": {
        "outside_poses": int(np.count_nonzero(~covered)), "outside_initial": outside_init, "no_return": n_empty}})
    name = cfg.name or out.name
    write_scenario(out, name, map_path, las, rows_out,
                   description=(f"Imported from ROS bag {Path(cfg.bag).name}: {cfg.scan_topic} scans, "
                                f"reference poses from {cfg.pose_topic} interpolated to the scan stamps, "
                                f"{init_text}."),
                   source=source)
    return ImportSummary(out, int(scans.index.size), int(rows.size), int(np.count_nonzero(~covered)),
                         outside_init, n_empty)


def _also_covered(cfg: BagImport, stream: PoseStream, topic: str, t: np.ndarray,
                  keep: np.ndarray) -> tuple[np.ndarray, int, np.ndarray]:
    """A second pose stream (initial poses or odometry) at the scan stamps ``t`` (s): its poses
    ``(len(t), 3)``, how many kept scans it does not cover, and ``keep`` without them."""
    poses, cov = interpolate_poses(stream.stamps, stream.poses, t, cfg.max_pose_gap_s)
    outside = int(np.count_nonzero(keep & ~cov))
    keep = keep & cov
    if not keep.any():
        raise BagError(f"{cfg.bag}: {topic} covers none of the scans on {cfg.scan_topic} "
                       f"that {cfg.pose_topic} covers (poses span {span(stream.stamps)})")
    return poses, outside, keep
