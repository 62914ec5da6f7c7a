"""Small ROS bags for the tests, written with rosbags' own writers: LaserScans simulated in the
bundled test room along a known path, reference poses of every supported kind, an
OccupancyGrid. Each item is plain data; :func:`write_bag` builds the messages for ROS 1 or 2."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tfloc import LaserSpec, load_map
from tfloc.maps.build import rasterize
from tfloc.maps.grid import GridMap

ROOT = Path(__file__).resolve().parents[1]
ROOM = ROOT / "data" / "maps" / "test-room.geojson"
T0 = 1_700_000_000.0  # s
LASER = LaserSpec(10.0, math.pi, math.radians(1.0), -math.pi / 2)  # 181 beams, like an LMS200
KINDS = ("ros1", "sqlite3", "mcap")
POSE_T = T0 + 0.02 * np.arange(120)  # reference poses at 50 Hz over the whole path (2.4 s)


def path_pose(t: np.ndarray) -> np.ndarray:
    """The robot's true pose ``(N, 3)`` at times ``t`` (s): along the room's free corridor
    (x 1.6…4.4 m, y 4 ± 0.25 m) in 2 s, turning from 0.3 to 1.5 rad."""
    s = np.clip((np.asarray(t, dtype=float) - T0) / 2.0, 0.0, 1.0)
    return np.column_stack((1.6 + 2.8 * s, 4.0 + 0.25 * np.sin(2 * math.pi * s), 0.3 + 1.2 * s))


def scan_times(n: int = 20) -> np.ndarray:
    """``n`` scan stamps at 10 Hz from ``T0 + 0.05`` s."""
    return T0 + 0.05 + 0.1 * np.arange(n)


def simulate(n: int = 20) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stamps, true poses and simulated ranges ``(n, 181)`` (inf = no return) in the test room."""
    t = scan_times(n)
    P = path_pose(t)
    return t, P, load_map(ROOM).raycast(P, LASER)


def room_grid(resolution: float = 0.05) -> GridMap:
    """The test room rasterised, as an OccupancyGrid would carry it."""
    return rasterize(load_map(ROOM), resolution, name="room")


@dataclass(frozen=True)
class ScanItem:
    topic: str
    t: float
    ranges: np.ndarray
    angle_min: float = LASER.angle_min
    angle_increment: float = LASER.resolution
    range_min: float = 0.05
    range_max: float = LASER.max_range
    frame: str = "laser"


@dataclass(frozen=True)
class PoseItem:
    topic: str
    msgtype: str  # PoseStamped | PoseWithCovarianceStamped | Odometry
    t: float
    pose: tuple[float, float, float]
    frame: str = "map"


@dataclass(frozen=True)
class TfItem:
    topic: str
    t: float
    transforms: tuple  # ((parent, child, (x, y, yaw)), ...)


@dataclass(frozen=True)
class GridItem:
    topic: str
    t: float
    grid: GridMap


def pose_items(topic: str, msgtype: str, t: np.ndarray, frame: str = "map") -> list[PoseItem]:
    return [PoseItem(topic, msgtype, float(ti), tuple(p), frame) for ti, p in zip(t, path_pose(t), strict=True)]


def scan_items(topic: str, t: np.ndarray, ranges: np.ndarray, **kw) -> list[ScanItem]:
    return [ScanItem(topic, float(ti), r, **kw) for ti, r in zip(t, ranges, strict=True)]


def _typestore(kind: str):
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    if kind != "ros1":
        return get_typestore(Stores.ROS2_HUMBLE)
    ts = get_typestore(Stores.ROS1_NOETIC)  # noetic's store lacks tf2_msgs: add it
    ts.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
    return ts


def _msg(ts, kind: str, item):
    T = ts.types
    sec = int(math.floor(item.t))

    def header(frame: str):
        stamp = T["builtin_interfaces/msg/Time"](sec=sec, nanosec=int(round((item.t - sec) * 1e9)))
        H = T["std_msgs/msg/Header"]
        return H(seq=0, stamp=stamp, frame_id=frame) if kind == "ros1" else H(stamp=stamp, frame_id=frame)

    def geo(x, y, yaw):
        return (T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
                T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)))

    if isinstance(item, ScanItem):
        r = np.asarray(item.ranges, dtype=np.float32)
        return "sensor_msgs/msg/LaserScan", T["sensor_msgs/msg/LaserScan"](
            header(item.frame), item.angle_min, item.angle_min + item.angle_increment * (r.size - 1),
            item.angle_increment, 0.0, 0.1, item.range_min, item.range_max, r, np.zeros(0, np.float32))
    if isinstance(item, PoseItem):
        pos, q = geo(*item.pose)
        pose = T["geometry_msgs/msg/Pose"](position=pos, orientation=q)
        mt = f"geometry_msgs/msg/{item.msgtype}" if item.msgtype != "Odometry" else "nav_msgs/msg/Odometry"
        if item.msgtype == "PoseStamped":
            return mt, T[mt](header=header(item.frame), pose=pose)
        cov = T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36))
        if item.msgtype == "PoseWithCovarianceStamped":
            return mt, T[mt](header=header(item.frame), pose=cov)
        twist = T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T["geometry_msgs/msg/Twist"](linear=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                                               angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)),
            covariance=np.zeros(36))
        return mt, T[mt](header=header(item.frame), child_frame_id="base_link", pose=cov, twist=twist)
    if isinstance(item, TfItem):
        trs = []
        for parent, child, (x, y, yaw) in item.transforms:
            _, q = geo(x, y, yaw)
            tr = T["geometry_msgs/msg/Transform"](translation=T["geometry_msgs/msg/Vector3"](x=x, y=y, z=0.0),
                                                  rotation=q)
            trs.append(T["geometry_msgs/msg/TransformStamped"](header=header(parent), child_frame_id=child,
                                                               transform=tr))
        return "tf2_msgs/msg/TFMessage", T["tf2_msgs/msg/TFMessage"](transforms=trs)
    if isinstance(item, GridItem):
        g = item.grid
        occ = np.where(np.isnan(g.occupancy), -1, np.round(100 * np.nan_to_num(g.occupancy))).astype(np.int8)
        pos, q = geo(g.origin[0], g.origin[1], 0.0)
        stamp = header("map").stamp
        info = T["nav_msgs/msg/MapMetaData"](map_load_time=stamp, resolution=g.resolution, width=g.shape[1],
                                             height=g.shape[0],
                                             origin=T["geometry_msgs/msg/Pose"](position=pos, orientation=q))
        return "nav_msgs/msg/OccupancyGrid", T["nav_msgs/msg/OccupancyGrid"](header=header("map"), info=info,
                                                                             data=occ.reshape(-1))
    raise TypeError(item)


def write_bag(path: Path, kind: str, items: list) -> Path:
    """Write ``items`` as a ROS 1 bag (``kind='ros1'``, ``path`` ends in ``.bag``) or a ROS 2 bag
    directory (``'sqlite3'`` or ``'mcap'``), in time order; returns the bag's path."""
    ts = _typestore(kind)
    items = sorted(items, key=lambda it: it.t)
    if kind == "ros1":
        from rosbags.rosbag1 import Writer

        writer = Writer(path)
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        writer = Writer(path, version=9, storage_plugin=StoragePlugin.SQLITE3 if kind == "sqlite3"
                        else StoragePlugin.MCAP)
    conns: dict[str, object] = {}
    with writer:
        for it in items:
            msgtype, msg = _msg(ts, kind, it)
            if it.topic not in conns:
                conns[it.topic] = writer.add_connection(it.topic, msgtype, typestore=ts)
            data = ts.serialize_ros1(msg, msgtype) if kind == "ros1" else ts.serialize_cdr(msg, msgtype)
            writer.write(conns[it.topic], int(round(it.t * 1e9)), data)
    return path


def bag_path(tmp: Path, kind: str, stem: str = "run") -> Path:
    return tmp / (f"{stem}.bag" if kind == "ros1" else f"{stem}-{kind}")


def gt_bag(path: Path, kind: str, t: np.ndarray, ranges: np.ndarray, extra: list = ()) -> Path:
    """A bag with scans on /scan and PoseStamped reference poses on /gt (plus ``extra`` items)."""
    return write_bag(path, kind, scan_items("/scan", t, ranges) + pose_items("/gt", "PoseStamped", POSE_T)
                     + list(extra))
