"""ROS 1 bags and ROS 2 bags (sqlite3 or mcap) read with the ``rosbags`` library: no ROS needed.

* ``sensor_msgs/LaserScan`` → :class:`ScanStream` (one laser spec per topic; ranges outside
  ``[range_min, range_max]`` or NaN become ``inf``, no return).
* ``geometry_msgs/PoseStamped``, ``geometry_msgs/PoseWithCovarianceStamped``,
  ``nav_msgs/Odometry``, or one ``parent → child`` frame pair of a ``tf2_msgs/TFMessage`` topic
  → :class:`PoseStream` (planar: x, y and the yaw of the quaternion).
* ``nav_msgs/OccupancyGrid`` → :class:`~tfloc.maps.grid.GridMap` (the last message on the topic).

Times are the header stamps in seconds (the bag's receive time when a stamp is zero). Every
error is a :class:`~tfloc.errors.BagError` whose message names the bag, the topic and the
message index (0-based, in bag order on that topic). ``rosbags`` is imported lazily: it is the
optional extra ``tfloc[ros]``.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.errors import BagError
from tfloc.maps.grid import GridMap

from .tum import quaternion_yaw

SCAN_TYPES = ("sensor_msgs/msg/LaserScan",)
POSE_TYPES = ("geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/PoseWithCovarianceStamped",
              "nav_msgs/msg/Odometry")
TF_TYPES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")
GRID_TYPES = ("nav_msgs/msg/OccupancyGrid",)


@dataclass(frozen=True, eq=False)
class ScanStream:
    """The LaserScan messages of one topic.

    Attributes:
        topic: the topic name.
        laser: the scanner (``max_range`` = ``range_max``, ``resolution`` = ``angle_increment``,
            ``fov`` = ``angle_increment · (n − 1)``, ``angle_min``), radians and metres.
        stamps: ``(N,)`` seconds.
        ranges: ``(N, n)`` metres, ``inf`` = no return.
        index: ``(N,)`` each scan's message index on the topic.
        frame_id: the header's frame.
        range_min: metres; shorter readings were set to ``inf``.
    """

    topic: str
    laser: LaserSpec
    stamps: np.ndarray
    ranges: np.ndarray
    index: np.ndarray
    frame_id: str
    range_min: float


@dataclass(frozen=True, eq=False)
class PoseStream:
    """Timed planar poses of one topic (or tf frame pair), sorted by strictly increasing stamp.

    Attributes: ``topic``; ``stamps`` ``(N,)`` s; ``poses`` ``(N, 3)`` (m, m, rad);
    ``frame_id`` (the frame the poses are given in) and ``child_frame_id`` (may be empty).
    """

    topic: str
    stamps: np.ndarray
    poses: np.ndarray
    frame_id: str
    child_frame_id: str = ""


def _why(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or "no detail"
    return f"{type(exc).__name__}: {text[:200]}"


def _stamp(header, t_ns: int) -> float:
    sec, nsec = int(header.stamp.sec), int(header.stamp.nanosec)
    return t_ns * 1e-9 if sec == 0 and nsec == 0 else sec + nsec * 1e-9


class Bag:
    """An open bag file (ROS 1 ``.bag``) or ROS 2 bag (directory, ``.db3`` or ``.mcap`` file).

    Use as a context manager: ``with Bag(path) as bag: scans = bag.scans("/scan")``."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._reader = None

    def __enter__(self) -> Bag:
        try:
            from rosbags.highlevel import AnyReader
        except ImportError:
            raise BagError("reading ROS bags needs the 'rosbags' library: pip install 'tfloc[ros]'") from None
        if not self.path.exists():
            raise BagError(f"{self.path}: no such bag file or directory")
        try:
            reader = AnyReader([self.path])
            reader.open()
        except Exception as exc:  # rosbags raises many kinds on corrupt input; report them as one
            raise BagError(f"{self.path}: cannot open bag ({_why(exc)}); a truncated or unindexed "
                           "recording must be reindexed first (rosbag reindex / ros2 bag reindex)") from None
        self._reader = reader
        return self

    def __exit__(self, *exc) -> None:
        if self._reader is not None:
            self._reader.close()
            self._reader = None

    @property
    def topics(self) -> dict[str, str]:
        """Topic name → message type (``pkg/msg/Name``) of every topic in the bag."""
        return {name: str(info.msgtype) for name, info in self._reader.topics.items()}

    def _connections(self, topic: str, kinds: tuple[str, ...]) -> list:
        topics = self.topics
        if topic not in topics:
            have = ", ".join(f"{t} [{m}]" for t, m in sorted(topics.items())) or "none"
            raise BagError(f"{self.path}: no topic {topic} in the bag (topics: {have})")
        if topics[topic] not in kinds:
            raise BagError(f"{self.path}: topic {topic} has type {topics[topic]}, expected "
                           f"{' or '.join(kinds)}")
        return [c for c in self._reader.connections if c.topic == topic]

    def messages(self, topic: str, kinds: tuple[str, ...]) -> Iterator[tuple[int, int, object]]:
        """Yield ``(index, bag time ns, message)`` of ``topic``; corrupt data raises a BagError
        naming the message index."""
        conns = self._connections(topic, kinds)
        count = sum(int(c.msgcount) for c in conns)
        i = 0
        gen = self._reader.messages(connections=conns)
        while True:
            try:
                item = next(gen, None)
                if item is None:
                    break
                con, t_ns, raw = item
                msg = self._reader.deserialize(raw, con.msgtype)
            except Exception as exc:  # truncated or corrupt storage, bad serialisation
                at = f"message {i}" if i < count else f"after message {i - 1} (of {count})"
                raise BagError(f"{self.path}: {topic} {at}: cannot read ({_why(exc)})") from None
            yield i, t_ns, msg
            i += 1
        if i == 0:
            raise BagError(f"{self.path}: topic {topic} has no messages")

    # -- conversions ---------------------------------------------------------------------------
    def scans(self, topic: str) -> ScanStream:
        """Every LaserScan of ``topic``. A change of beam count, angles or range limits within
        the topic is an error naming the message."""
        ref = None
        stamps, rows, index = [], [], []
        for i, t_ns, m in self.messages(topic, SCAN_TYPES):
            where = f"{self.path}: {topic} message {i}"
            spec = (len(m.ranges), float(m.angle_min), float(m.angle_increment), float(m.range_min),
                    float(m.range_max))
            n, amin, inc, rmin, rmax = spec
            if not (math.isfinite(inc) and inc != 0.0):
                raise BagError(f"{where}: angle_increment is {inc!r}, must be a finite non-zero angle")
            if not math.isfinite(amin):
                raise BagError(f"{where}: angle_min is {amin!r}, must be finite")
            if not (math.isfinite(rmax) and rmax > 0 and math.isfinite(rmin) and 0 <= rmin < rmax):
                raise BagError(f"{where}: range_min {rmin!r} / range_max {rmax!r} are not 0 ≤ min < max")
            if n < 2:
                raise BagError(f"{where}: {n} beams, need at least 2")
            if ref is None:
                ref = (spec, m.header.frame_id)
            elif spec != ref[0]:
                names = ("beam count", "angle_min", "angle_increment", "range_min", "range_max")
                k = next(k for k in range(5) if spec[k] != ref[0][k])
                raise BagError(f"{where}: {names[k]} {spec[k]:g} differs from message 0's {ref[0][k]:g}; "
                               "one topic must keep one laser spec")
            r = np.asarray(m.ranges, dtype=float)
            with np.errstate(invalid="ignore"):
                r = np.where(np.isfinite(r) & (r >= rmin) & (r <= rmax), r, np.inf)
            rows.append(r[::-1] if inc < 0 else r)
            stamps.append(_stamp(m.header, t_ns))
            index.append(i)
        (n, amin, inc, rmin, rmax), frame = ref
        if inc < 0:  # a mirrored scanner: store the beams counter-clockwise
            amin, inc = amin + inc * (n - 1), -inc
        laser = LaserSpec(rmax, inc * (n - 1), inc, amin)
        return ScanStream(topic, laser, np.array(stamps), np.vstack(rows), np.array(index, dtype=int),
                          str(frame), rmin)

    def poses(self, topic: str, frames: tuple[str, str] | None = None) -> PoseStream:
        """Planar poses of a pose topic, or of the ``frames = (parent, child)`` transform on a
        tf topic (the inverse transform ``child → parent`` is inverted). Sorted by stamp; of
        several poses with one stamp the last is kept."""
        types = self.topics.get(topic)
        if types in TF_TYPES:
            if frames is None:
                raise BagError(f"{self.path}: {topic} is a tf topic: name the frame pair (parent child)")
            return self._tf_poses(topic, frames)
        if frames is not None and types is not None:
            raise BagError(f"{self.path}: {topic} has type {types}; a frame pair applies to tf topics only")
        stamps, poses, frame, child = [], [], "", ""
        for i, t_ns, m in self.messages(topic, POSE_TYPES):
            p = m.pose if m.__msgtype__ == "geometry_msgs/msg/PoseStamped" else m.pose.pose
            poses.append(_planar(p.position, p.orientation, f"{self.path}: {topic} message {i}"))
            stamps.append(_stamp(m.header, t_ns))
            frame, child = m.header.frame_id, getattr(m, "child_frame_id", "")
        return _sorted_stream(topic, stamps, poses, frame, child)

    def _tf_poses(self, topic: str, frames: tuple[str, str]) -> PoseStream:
        parent, child = (f.strip("/") for f in frames)
        stamps, poses, seen = [], [], set()
        for i, t_ns, m in self.messages(topic, TF_TYPES):
            for tr in m.transforms:
                pair = (tr.header.frame_id.strip("/"), tr.child_frame_id.strip("/"))
                seen.add(pair)
                if pair not in ((parent, child), (child, parent)):
                    continue
                x, y, th = _planar(tr.transform.translation, tr.transform.rotation,
                                   f"{self.path}: {topic} message {i} ({pair[0]} → {pair[1]})")
                if pair == (child, parent):  # invert
                    c, s = math.cos(th), math.sin(th)
                    x, y, th = -(c * x + s * y), s * x - c * y, -th
                poses.append((x, y, th))
                stamps.append(_stamp(tr.header, t_ns))
        if not poses:
            have = ", ".join(f"{a} → {b}" for a, b in sorted(seen)) or "none"
            raise BagError(f"{self.path}: {topic} has no transform {parent} → {child} (frame pairs: {have})")
        return _sorted_stream(topic, stamps, poses, parent, child)

    def grid(self, topic: str) -> GridMap:
        """The last OccupancyGrid of ``topic`` (cells −1 = unknown, 0…100 = occupancy %)."""
        last = None
        for i, _t, m in self.messages(topic, GRID_TYPES):
            last = (i, m)
        i, m = last
        where = f"{self.path}: {topic} message {i}"
        info = m.info
        W, H, res = int(info.width), int(info.height), float(info.resolution)
        data = np.asarray(m.data).astype(int)
        if W < 1 or H < 1 or data.size != W * H:
            raise BagError(f"{where}: {data.size} cells for a {W} x {H} grid")
        if not (math.isfinite(res) and res > 0):
            raise BagError(f"{where}: resolution {res!r} must be a positive number of metres")
        ox, oy, yaw = _planar(info.origin.position, info.origin.orientation, where)
        if abs(yaw) > 1e-9:
            raise BagError(f"{where}: rotated grids (origin yaw {yaw:g} rad) are not supported")
        if data.min() < -1 or data.max() > 100:
            raise BagError(f"{where}: cell values must be -1 (unknown) or 0…100, found {data.min()}…{data.max()}")
        occ = np.where(data < 0, np.nan, data / 100.0).reshape(H, W)
        return GridMap(occ, res, (ox, oy), name=topic.strip("/").replace("/", "-") or "map")


def _planar(position, orientation, where: str) -> tuple[float, float, float]:
    """x, y (m) and yaw (rad) of a ROS position and quaternion; bad values name ``where``."""
    x, y = float(position.x), float(position.y)
    q = [float(orientation.x), float(orientation.y), float(orientation.z), float(orientation.w)]
    if not (math.isfinite(x) and math.isfinite(y) and all(math.isfinite(v) for v in q)):
        raise BagError(f"{where}: pose is not finite")
    if sum(v * v for v in q) < 1e-12:
        raise BagError(f"{where}: orientation quaternion is zero")
    return x, y, float(quaternion_yaw(*q))


def _sorted_stream(topic: str, stamps: list, poses: list, frame: str, child: str) -> PoseStream:
    t = np.asarray(stamps, dtype=float)
    p = np.asarray(poses, dtype=float).reshape(-1, 3)
    order = np.argsort(t, kind="stable")
    t, p = t[order], p[order]
    keep = np.append(t[1:] != t[:-1], True)  # the last of equal stamps
    return PoseStream(topic, t[keep], p[keep], str(frame), str(child))
