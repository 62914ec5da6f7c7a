"""``cartographer``: Cartographer's pure-localization loop as its users run it (cartographer_ros
``backpack_2d_localization.lua`` on a 2D laser with wheel odometry: ``use_odometry = true``,
``use_imu_data = false``, online correlative scan matching on).

* **Local SLAM** (:mod:`._local`): each scan matched against the trajectory's *own* submaps
  (never the map), inserted when the motion filter lets it; an inserted scan is a node.
* **Frozen submaps** (:mod:`._frozen`): the map's probability grid tiled as submaps (the suite
  hands trackers the map, not the mapping run's ``.pbstream``; docs/baselines/cartographer.md).
* **Constraints** (``PoseGraph2D::ComputeConstraint``): every new node against every frozen submap.
  While the trajectory is *connected* (a constraint to the map found within
  ``global_constraint_search_after_n_seconds``), a submap within ``max_constraint_distance`` of
  the node is searched in the branch-and-bound window about the node's global pose when its
  ``FixedRatioSampler`` (``sampling_ratio``) pulses; otherwise, one sampler per trajectory
  (``global_sampling_ratio``) decides a full-submap search. Found poses (score ≥ ``min_score``,
  ``global_localization_min_score`` for full searches) are refined by the Ceres scan matcher
  with the constraint builder's weights.
* **Optimisation** (:mod:`._optimize`) after more than ``optimize_every_n_nodes`` nodes since the
  last: the trajectory's nodes and submaps, the frozen submaps fixed; then the constraints found
  mark the trajectory connected, and the pure-localization trimmer keeps the last
  ``max_submaps_to_keep`` submaps and their nodes.
* **Published pose**: the local→global transform of the last optimisation (the newest optimised
  submap's global pose ∘ its local pose⁻¹; before the first, the start pose) ∘ the scan's local pose.

The start pose: the local frame's origin is the robot at ``start`` (cartographer_ros's
``initial_pose``); the trajectory is not connected until a constraint is found, as Cartographer.
``info["constraint_score"]``: the score of the last constraint found (0 before any), the
confidence it reports. Own-trajectory loop closures and matching old map nodes against new
local submaps are left out (the map has no nodes here).
"""

from __future__ import annotations

import math

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, check_ranges
from tfloc.core.traits import Confidence
from tfloc.errors import InvalidProblemError, ParameterError

from . import _ceres
from ._config import Config
from ._frozen import frozen_submaps, search, search_full
from ._local import Insertion, LocalSlam
from ._optimize import Blocks, solve

_MAX_DEPTH = 12  # as bnb-global's precomputation grids


class _Sampler:
    """``common::FixedRatioSampler``: pulses so that the share of true pulses stays at ``ratio``."""

    def __init__(self, ratio: float) -> None:
        self.ratio, self.pulses, self.samples = ratio, 0, 0

    def pulse(self) -> bool:
        self.pulses += 1
        if self.samples / self.pulses < self.ratio:
            self.samples += 1
            return True
        return False


class CartographerTracker:
    """Cartographer's pure-localization loop run scan by scan (module notes)."""

    name = "cartographer"
    METHOD = "cartographer"  # (tfloc.core.traits)
    CONFIDENCE = Confidence("constraint_score", True, "the score of the last constraint to the map")
    kind = "tracker"
    CONFIG = Config

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        self.config = resolve_params(Config, config, overrides)
        if self.config.branch_and_bound_depth > _MAX_DEPTH:
            raise ParameterError(f"branch_and_bound_depth must be ≤ {_MAX_DEPTH}, got "
                                 f"{self.config.branch_and_bound_depth}", ("branch_and_bound_depth",))
        self._local: LocalSlam | None = None

    # -- the Tracker protocol ----------------------------------------------------------------
    def warm(self, map: Map, laser: LaserSpec, ranges: np.ndarray, pose: Pose) -> None:
        """Untimed: the frozen submaps and one step of a throwaway copy (numba kernels compiled)."""
        other = CartographerTracker(self.config)
        other.start(map, laser, pose)
        other.step(ranges, Pose(0.0, 0.0, 0.0), 0.0, "warm-up")
        if other._frozen:
            search(other._frozen[0], other._laser.to_points(check_ranges(ranges, laser, "warm-up"))[:50], pose,
                   0.2, 0.05, 0.0)

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        if not pose.is_finite():
            raise InvalidProblemError(f"cartographer: starting pose is not finite: {pose}")
        c = self.config
        self._frozen = frozen_submaps(map, c.frozen_submap_size, c.branch_and_bound_depth)
        if not self._frozen:
            raise InvalidProblemError("cartographer: the map has no occupied cell (no frozen submap to localize in)")
        self._laser = laser
        self._local = LocalSlam(c)
        self._local_to_global = pose
        self._odom = Pose(0.0, 0.0, 0.0)
        self._nodes: list[dict] = []  # kept nodes, oldest first: index, stamp, local, odom, global
        self._submaps: list[dict] = []  # kept local submaps, oldest first: obj, local, global
        self._intra: list[tuple[int, int, np.ndarray]] = []  # (submap id, node index, z)
        self._inter: list[tuple[int, int, np.ndarray, float]] = []  # (frozen index, node index, z, stamp)
        self._pending: list[tuple[int, int, np.ndarray, float]] = []
        self._samplers = [_Sampler(c.sampling_ratio) for _ in self._frozen]
        self._global_sampler = _Sampler(c.global_sampling_ratio)
        self._last_connection = 0.0 if c.start_connected else -math.inf  # (stamps relative to the first)
        self._t0: float | None = None
        self._since_optimisation = 0
        self._next_node = 0
        self._score = 0.0
        self.optimisations = 0

    def predict(self, odom_delta: Pose) -> Pose:
        if self._local is None:
            raise RuntimeError("CartographerTracker.predict before start")
        return self._local_to_global.compose(self._local.pose.compose(odom_delta))

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        if self._local is None:
            raise RuntimeError("CartographerTracker.step before start")
        if not odom_delta.is_finite() or stamp is None or not math.isfinite(stamp):
            raise InvalidProblemError(f"{where}: odometry increment or stamp is not finite")
        points = self._laser.to_points(check_ranges(ranges, self._laser, where))
        if self._t0 is None:
            self._t0 = float(stamp)
        stamp = float(stamp) - self._t0
        self._odom = self._odom.compose(odom_delta)
        local, ins, info = self._local.step(points, odom_delta, float(stamp))
        found = 0
        if ins is not None:
            found = self._add_node(ins, float(stamp))
        info.update(node=ins is not None, constraints_found=found, constraint_score=self._score,
                    connected=bool(stamp < self._last_connection + self.config.global_constraint_search_after_n_seconds))
        return Estimate(self._local_to_global.compose(local), True, 1, 0, info)

    def reset(self, pose: Pose) -> None:
        """Publish ``pose`` for the current scan: the local→global transform set to match."""
        if self._local is None:
            raise RuntimeError("CartographerTracker.reset before start")
        self._local_to_global = pose.compose(self._local.pose.inverse())

    # -- the pose graph ----------------------------------------------------------------------
    def _submap_record(self, sub) -> dict:  # noqa: ANN001 - a _submaps.Submap
        for rec in self._submaps:
            if rec["obj"] is sub:
                return rec
        local = Pose(sub.origin_xy[0], sub.origin_xy[1], 0.0)
        if self._submaps:  # InitializeGlobalSubmapPoses: from the previous submap's global pose
            prev = self._submaps[-1]
            glob = prev["global"].compose(prev["local"].inverse()).compose(local)
        else:
            glob = self._local_to_global.compose(local)
        rec = {"obj": sub, "local": local, "global": glob, "id": id(sub)}
        self._submaps.append(rec)
        return rec

    def _add_node(self, ins: Insertion, stamp: float) -> int:
        c = self.config
        recs = [self._submap_record(s) for s in ins.submaps]
        front = recs[0]
        glob = front["global"].compose(front["local"].inverse()).compose(ins.pose)
        k = self._next_node
        self._next_node += 1
        self._nodes.append({"index": k, "stamp": stamp, "local": ins.pose, "odom": self._odom, "global": glob})
        for rec in recs:
            self._intra.append((rec["id"], k, rec["local"].inverse().compose(ins.pose).as_array()))
        found = 0
        for f, sub in enumerate(self._frozen):
            connected = stamp < self._last_connection + c.global_constraint_search_after_n_seconds
            if connected:
                rel = sub.pose.inverse().compose(glob)
                if math.hypot(rel.x, rel.y) > c.max_constraint_distance or not self._samplers[f].pulse():
                    continue
                hit = search(sub, ins.points, glob, c.fast_linear_search_window,
                             math.radians(c.fast_angular_search_window_deg), c.min_score)
            elif self._global_sampler.pulse():
                hit = search_full(sub, ins.points, c.global_localization_min_score)
            else:
                continue
            if hit is None or len(ins.points) == 0:
                continue
            pose, _ = _ceres.match(sub.grid, ins.points, hit[0], hit[0], c.constraint_occupied_space_weight,
                                   c.constraint_translation_weight, c.constraint_rotation_weight,
                                   c.constraint_max_num_iterations)
            self._pending.append((f, k, sub.pose.inverse().compose(pose).as_array(), stamp))
            self._score = hit[1]
            found += 1
        self._since_optimisation += 1
        if c.optimize_every_n_nodes > 0 and self._since_optimisation > c.optimize_every_n_nodes:
            self._optimise()
        return found

    def _optimise(self) -> None:
        """``RunOptimization``, then connectivity and the pure-localization trimmer (module notes)."""
        c = self.config
        self._inter.extend(self._pending)
        new, self._pending = self._pending, []
        self._since_optimisation = 0
        if self._inter:
            self._solve()
        for _, _, _, stamp in new:
            self._last_connection = max(self._last_connection, stamp)
        self._trim(c.max_submaps_to_keep)

    def _solve(self) -> None:
        c = self.config
        sub_var = {rec["id"]: v for v, rec in enumerate(self._submaps)}
        node_var = {n["index"]: len(self._submaps) + v for v, n in enumerate(self._nodes)}
        x0 = np.array([r["global"].as_array() for r in self._submaps] + [n["global"].as_array() for n in self._nodes])
        rows: list[tuple] = []  # (start var or -1, start pose, end var, z, w_t, w_r, robust)
        zero = np.zeros(3)
        for sid, k, z in self._intra:
            rows.append((sub_var[sid], zero, node_var[k], z, c.matcher_translation_weight,
                         c.matcher_rotation_weight, False))
        for f, k, z, _ in self._inter:
            rows.append((-1, self._frozen[f].pose.as_array(), node_var[k], z, c.loop_closure_translation_weight,
                         c.loop_closure_rotation_weight, True))
        for a, b in zip(self._nodes[:-1], self._nodes[1:], strict=True):
            if b["index"] != a["index"] + 1:
                continue
            rows.append((node_var[a["index"]], zero, node_var[b["index"]],
                         a["odom"].inverse().compose(b["odom"]).as_array(), c.odometry_translation_weight,
                         c.odometry_rotation_weight, False))
            rows.append((node_var[a["index"]], zero, node_var[b["index"]],
                         a["local"].inverse().compose(b["local"]).as_array(), c.local_slam_pose_translation_weight,
                         c.local_slam_pose_rotation_weight, False))
        cols = list(zip(*rows, strict=True))
        blocks = Blocks(np.array(cols[0], dtype=np.int64), np.array(cols[1], dtype=float),
                        np.array(cols[2], dtype=np.int64), np.array(cols[3], dtype=float),
                        np.array(cols[4], dtype=float), np.array(cols[5], dtype=float), np.array(cols[6], dtype=bool))
        x, _ = solve(x0, blocks, c.huber_scale, c.optimization_max_num_iterations)
        for v, rec in enumerate(self._submaps):
            rec["global"] = Pose.from_array(x[v])
        for n in self._nodes:
            n["global"] = Pose.from_array(x[node_var[n["index"]]])
        last = self._submaps[-1]
        self._local_to_global = last["global"].compose(last["local"].inverse())
        self.optimisations += 1

    def _trim(self, keep: int) -> None:
        """``PureLocalizationTrimmer``: drop all but the last ``keep`` submaps, the nodes in none of
        the kept ones and every constraint on what was dropped."""
        if len(self._submaps) <= keep:
            return
        self._submaps = self._submaps[-keep:]
        kept_ids = {r["id"] for r in self._submaps}
        self._intra = [t for t in self._intra if t[0] in kept_ids]
        kept_nodes = {k for _, k, _ in self._intra}
        self._nodes = [n for n in self._nodes if n["index"] in kept_nodes]
        self._inter = [t for t in self._inter if t[1] in kept_nodes]
        self._pending = [t for t in self._pending if t[1] in kept_nodes]


REGISTRY = {"cartographer": {"class": "CartographerTracker", "docs": "baselines/cartographer.md", "files": ["baselines/cartographer/"], "summary": (
    "Cartographer's pure-localization loop (`backpack_2d_localization.lua`, wheel odometry, "
    "online CSM): local SLAM on its own submaps, constraints to frozen submaps of the map by "
    "branch and bound then Ceres, the sparse pose optimisation every 20 nodes, the "
    "pure-localization trimmer; publishes the map-frame pose "
    "([docs/baselines/cartographer.md](baselines/cartographer.md))")}}
