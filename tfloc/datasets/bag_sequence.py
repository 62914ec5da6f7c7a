"""A sequence dataset (tracking) from a bag: the scans in time order with the robot's odometry
at each, with or without reference poses.

With reference poses the robot starts at the reference of the first scan and every row holds
its true pose. Without them (what a robot owner has: scans, odometry, a map) every ``true_*`` is
empty, ``scenario.json`` says ``"truth": false``, and the start is ``--initial-pose`` (the robot's
pose, map frame), ``--initial-topic`` (e.g. AMCL's ``/amcl_pose``, at the first scan it covers)
or found by a global matcher (:mod:`tfloc.datasets.first_pose`); ``generator.start`` says which,
with the matcher's score and whether another place scored about as well. Scans the odometry does
not cover (a gap longer than ``--max-pose-gap``) are skipped and their stretches recorded in
``generator.odometry_gaps``; so are scans without a return (``generator.scans_without_return``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tfloc.core.pose import Pose
from tfloc.errors import BagError
from tfloc.io.scenario import SEQUENCE, Scan, usable_sequence, write_scenario

from .bag_files import ImportSummary, returning_rows, save_map, source_record, span, stretches
from .first_pose import FirstPose, global_first_pose
from .interpolate import interpolate_poses


def import_sequence(cfg, scans, pick: np.ndarray, t: np.ndarray, truth: np.ndarray, covered: np.ndarray,
                    init, odom, grid, ref) -> ImportSummary:
    """Write the sequence of a :class:`~tfloc.datasets.from_bag.BagImport` ``cfg`` from the
    bag's streams (``ref`` and ``init`` may be None; ``truth`` and ``covered`` are the reference
    at the picked scans' stamps ``t`` and where it covers them)."""
    out = Path(cfg.out)
    odom_p, cov_o = interpolate_poses(odom.stamps, odom.poses, t, cfg.max_pose_gap_s)
    keep = covered & cov_o
    if not keep.any():
        also = f" that {cfg.pose_topic} covers" if ref is not None else ""
        raise BagError(f"{cfg.bag}: {cfg.odom_topic} covers none of the scans on {cfg.scan_topic}{also} "
                       f"(poses span {span(odom.stamps)})")
    gaps = stretches(covered & ~cov_o, t, scans.index[pick])
    outside_odom = int(np.count_nonzero(covered & ~cov_o))
    # a sequence's stamps increase strictly: a scan not later than every earlier one is dropped
    late = t > np.maximum.accumulate(np.concatenate([[-np.inf], t[:-1]]))
    outside_odom += int(np.count_nonzero(keep & ~late))
    keep &= late
    outside_init, init_p = 0, None
    if init is not None:  # the start: the initial topic at the first scan it covers
        init_p, cov_i = interpolate_poses(init.stamps, init.poses, t, cfg.max_pose_gap_s)
        first = np.flatnonzero(keep & cov_i)
        if not first.size:
            raise BagError(f"{cfg.bag}: {cfg.initial_topic} covers none of the scans on {cfg.scan_topic} "
                           f"that {cfg.odom_topic} covers (poses span {span(init.stamps)})")
        outside_init = int(np.count_nonzero(keep[:first[0]]))
        keep[:first[0]] = False
    las = scans.laser
    rows, no_return = returning_rows(cfg, scans, pick, keep)
    n_empty = int(np.count_nonzero(no_return))
    empty = stretches(no_return, t, scans.index[pick])
    off = cfg.laser_offset
    odom_l = [Pose.from_array(odom_p[k]).compose(off) for k in rows]
    true_p = [Pose.from_array(truth[k]).compose(off) for k in rows] if ref is not None else [None] * rows.size

    from tfloc.io.maps import load_map

    the_map = grid if grid is not None else load_map(cfg.map_file)
    if ref is not None and not the_map.in_bounds(np.array([[p.x, p.y] for p in true_p])).any():
        raise BagError(f"{cfg.bag}: none of the {cfg.pose_topic} poses at the scans lies inside the map "
                       f"(bounds {tuple(round(b, 2) for b in the_map.bounds)} m); are they in the map frame?")
    start = _start(cfg, true_p[0], init_p[rows[0]] if init_p is not None else None, the_map, las,
                   scans.ranges[pick[rows[:cfg.initial_scans]]], odom_l[:cfg.initial_scans])
    seq = [Scan(f"s{scans.index[pick[k]]:05d}", "sequence", scans.ranges[pick[k]], start.pose if i == 0 else None,
                tp, stamp=float(t[k]), odom=o)
           for i, (k, tp, o) in enumerate(zip(rows, true_p, odom_l, strict=True))]
    usable_sequence(seq, the_map, str(cfg.bag), BagError)
    out.mkdir(parents=True, exist_ok=True)
    map_path = save_map(cfg, grid, out)
    skipped = {"outside_poses": int(np.count_nonzero(~covered)), "outside_odom": outside_odom, "no_return": n_empty}
    if init is not None:
        skipped["before_initial"] = outside_init
    how = {"initial_topic": cfg.initial_topic} if init is not None else {}
    source = source_record(cfg, scans, ref, rows, {"how": how, "skipped": skipped})
    generator = {"command": "tfloc import-bag", "start": start.record(), "odometry_gaps": list(gaps),
                 "scans_without_return": list(empty)}
    truth_text = (f"reference poses from {cfg.pose_topic}" if ref is not None else
                  "no reference poses (true_* empty: tracked, not scored)")
    write_scenario(out, cfg.name or out.name, map_path, las, seq,
                   description=(f"Imported from ROS bag {Path(cfg.bag).name} as a sequence: {cfg.scan_topic} "
                                f"scans in time order, odometry from {cfg.odom_topic} and {truth_text}, "
                                f"interpolated to the scan stamps; {start.text()}."),
                   mode=SEQUENCE, condition={"name": "bag"}, truth=ref is not None, generator=generator,
                   source=source)
    return ImportSummary(out, int(scans.index.size), int(rows.size), skipped["outside_poses"], outside_init,
                         n_empty, outside_odom, gaps, start)


def _start(cfg, true0: Pose | None, init0: np.ndarray | None, the_map, laser, ranges: np.ndarray,
           odom: list[Pose]) -> FirstPose:
    """The laser's pose at the first scan: the reference, ``--initial-pose`` or the initial
    topic (both the robot's, composed with the laser offset), or a global matcher's answer."""
    off = cfg.laser_offset
    if true0 is not None:
        return FirstPose(true0, "reference", cfg.pose_topic)
    if cfg.initial_pose is not None:
        return FirstPose(cfg.initial_pose.compose(off), "initial-pose")
    if init0 is not None:
        return FirstPose(Pose.from_array(init0).compose(off), "initial-topic", cfg.initial_topic)
    return global_first_pose(the_map, laser, ranges, odom, cfg.initial_matcher, where=str(cfg.bag))
