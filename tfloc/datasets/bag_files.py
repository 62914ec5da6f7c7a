"""What both kinds of bag import share: the summary they return, the map copied into the
dataset, the ``source`` record of ``scenario.json`` and the stretches of scans a pose stream
(the odometry) does not cover."""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from tfloc.errors import BagError


@dataclass(frozen=True)
class ImportSummary:
    """What an import kept and skipped (counts of scan messages); for a sequence, the stretches
    the odometry did not cover (:func:`stretches`) and how its start was found (a
    :class:`~tfloc.datasets.first_pose.FirstPose`)."""

    path: Path
    messages: int
    kept: int
    outside_poses: int
    outside_initial: int
    no_return: int
    outside_odom: int = 0
    odometry_gaps: tuple[dict, ...] = ()
    start: object = None


def span(stamps: np.ndarray) -> str:
    """``t=first…last s (N poses)`` of a pose stream, for messages."""
    return f"t={stamps[0]:.3f}…{stamps[-1]:.3f} s ({stamps.size} poses)"


def returning_rows(cfg: Any, scans: Any, pick: np.ndarray, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The picked scans to import: those ``keep`` marks that have a return, the first
    ``cfg.limit`` of them (all if 0); and the kept scans without any return (a mask over
    ``pick``). One line naming the bag and topic where none is left."""
    empty = keep & (scans.laser.valid(scans.ranges[pick]).sum(axis=1) == 0)
    rows = np.flatnonzero(keep & ~empty)
    if cfg.limit:
        rows = rows[:cfg.limit]
    if rows.size == 0:
        raise BagError(f"{cfg.bag}: no scan on {cfg.scan_topic} is left to import (all lack a return)")
    return rows, empty


def stretches(mask: np.ndarray, t: np.ndarray, index: np.ndarray) -> tuple[dict, ...]:
    """The maximal runs of scans in ``mask`` (scans at stamps ``t``, s, with message indices
    ``index``): first and last message, scans, stamps (s) and the seconds they span."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(np.int8))
    out = []
    for a, b in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True):
        out.append({"first_message": int(index[a]), "last_message": int(index[b]), "scans": int(b - a + 1),
                    "from_s": round(float(t[a]), 6), "to_s": round(float(t[b]), 6),
                    "seconds": round(float(t[b] - t[a]), 3)})
    return tuple(out)


def gaps_text(gaps: tuple[dict, ...], topic: str) -> str:
    """One clause for the import summary: how many scans in how many stretches ``topic`` missed."""
    if not gaps:
        return ""
    n = sum(g["scans"] for g in gaps)
    first = ", ".join(f"messages {g['first_message']}…{g['last_message']} ({g['seconds']:.2f} s)"
                      for g in gaps[:3])
    more = f" and {len(gaps) - 3} more" if len(gaps) > 3 else ""
    return f"{topic} missing for {n} scans in {len(gaps)} stretch(es): {first}{more}"


def source_record(cfg, scans, ref, rows: np.ndarray, extra: dict) -> dict:
    """``scenario.json``'s ``source``: the bag, topics, frames and laser as read, the import's
    options and the counts (``extra`` adds the kind's own keys)."""
    off, las = cfg.laser_offset, scans.laser
    return {"bag": str(cfg.bag), "scan_topic": cfg.scan_topic, "pose_topic": cfg.pose_topic,
            "pose_frames": list(cfg.pose_frames) if cfg.pose_frames else None,
            **({"odom_topic": cfg.odom_topic, "odom_frames": list(cfg.odom_frames) if cfg.odom_frames else None}
               if cfg.odom_topic else {}),
            "map_topic": cfg.map_topic, "laser_frame": scans.frame_id,
            "pose_frame": ref.frame_id if ref is not None else None,
            "laser_offset": [off.x, off.y, off.theta],
            "angle_min": las.angle_min, "angle_increment": las.resolution, "range_min": scans.range_min,
            "range_max": las.max_range, "n_beams": las.n_beams, "every": cfg.every,
            "max_pose_gap_s": cfg.max_pose_gap_s, **extra.pop("how", {}),
            "scan_messages": int(scans.index.size), "imported": int(rows.size), **extra}


def save_map(cfg, grid, out: Path) -> Path:
    """Put the map into the dataset directory (``cfg.map_file`` copied, or the OccupancyGrid
    ``grid`` from the bag written as ``map.yaml``); return its path."""
    if grid is not None:
        from tfloc.io.rosmap import write_ros_map

        return write_ros_map(grid, out / "map.yaml")
    src = Path(cfg.map_file)
    if src.suffix.lower() not in (".yaml", ".yml"):
        return Path(shutil.copyfile(src, out / src.name))
    doc = yaml.safe_load(src.read_text())
    img = src.parent / doc["image"]
    shutil.copyfile(img, out / img.name)
    doc["image"] = img.name
    dst = out / src.name
    dst.write_text(f"# copied from {src} by tfloc import-bag\n" + yaml.safe_dump(doc, sort_keys=False))
    return dst
