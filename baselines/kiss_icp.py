"""``kiss-icp``: KISS-ICP's own registration of the real scan against a voxel map of the map.

Inputs are the map, the laser spec, the real scan and the initial pose (never the truth).
KISS-ICP's ``Registration.align_points_to_map`` runs unchanged on a ``VoxelHashMap`` of the map's
samples. Choices and why (the detail and the measurements: ``docs/baselines/kiss-icp.md``):

* **Scan at z = 0**, every valid beam, no deskewing or downsampling (on one 2D scan every point
  helps).
* **Target**: the map's samples every ``map_spacing``, one ``VoxelHashMap`` per voxel size, built
  once per map; not cropped (the search visits only the 27 voxels around each scan point).
* **Voxel schedule** ``voxel_sizes``, each stage from the last result: the neighbour-voxel search
  makes the voxel the correspondence gate, so KISS-ICP's default voxel (max_range / 100) alone
  converges only from small offsets. Gate ``gate_factor`` × voxel, Geman–McClure kernel
  ``kernel_factor`` × voxel; KISS-ICP's defaults otherwise, one thread (one worker per core).
* **Projected onto SE(2)** after every stage; ``converged`` = at least ``min_inlier_fraction`` of
  the scan points within the last voxel of a map point (a self-check).

**Amortised per map** (``prepare``): the samples, their KD-tree (inlier check, ``score``) and the
voxel maps. **Per scan**: KISS-ICP's registration and the inlier check.

``score(problem, pose)``: the mean Geman–McClure cost ``r² / (κ + r²)`` of each scan point's
distance ``r`` to its nearest map sample (κ the last stage's kernel; none within the last voxel: 1).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from kiss_icp.mapping import VoxelHashMap
from kiss_icp.registration import Registration

from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem
from tfloc.core.traits import Confidence
from tfloc.maps.cache import cached, map_geometry

from ._geometry import embed_z0, matrix_to_pose, pose_to_matrix


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`KissIcpMatcher` (metres)."""

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("voxel_sizes", "gate_factor", "kernel_factor", "map_spacing"),
        ">= 0": ("convergence_criterion",),
        ">= 1": ("max_points_per_voxel", "max_num_iterations", "max_num_threads"),
        "[0, 1]": ("min_inlier_fraction",)}

    voxel_sizes: tuple[float, ...] = (2.0, 1.0, 0.3, 0.1)  #: voxel size per stage, coarse first (m)
    gate_factor: float = 3.0  #: correspondence gate per stage, in voxels
    kernel_factor: float = 1.0  #: Geman–McClure kernel per stage, in voxels
    max_points_per_voxel: int = 20  #: KISS-ICP's points per voxel
    max_num_iterations: int = 500  #: KISS-ICP's ICP iterations per stage
    convergence_criterion: float = 1e-4  #: KISS-ICP's stop on the update's norm
    max_num_threads: int = 1  #: KISS-ICP's threads
    map_spacing: float = 0.02  #: sampling of the map's geometry (metres)
    min_inlier_fraction: float = 0.5  #: converged needs this share of scan points near the map


def _voxel_map(problem_map: object, voxel: float, max_points: int, spacing: float) -> VoxelHashMap:
    """The cached KISS-ICP voxel map of the whole map's geometry at one voxel size."""

    def build() -> VoxelHashMap:
        vm = VoxelHashMap(voxel_size=voxel, max_distance=np.inf, max_points_per_voxel=max_points)
        vm.add_points(embed_z0(map_geometry(problem_map, spacing).points))
        return vm

    return cached(problem_map, ("kiss-voxels", round(voxel, 9), max_points, round(spacing, 9)), build)


class KissIcpMatcher:
    """KISS-ICP registration to the map with a voxel schedule (see the module docstring)."""

    name = "kiss-icp"
    CONFIDENCE = Confidence("inlier_fraction", True, "the share of points within the last gate")

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        self.config = resolve_params(Config, config, overrides)
        self._registration = Registration(max_num_iterations=self.config.max_num_iterations,
                                          convergence_criterion=self.config.convergence_criterion,
                                          max_num_threads=self.config.max_num_threads)

    def prepare(self, problem: Problem) -> None:
        """Build the voxel maps and the sampled geometry (once per map; untimed by the harness)."""
        cfg = self.config
        for voxel in cfg.voxel_sizes:
            _voxel_map(problem.map, voxel, cfg.max_points_per_voxel, cfg.map_spacing)
        map_geometry(problem.map, cfg.map_spacing)

    def localize(self, problem: Problem) -> Estimate:
        """Register the real scan to the map, starting from ``problem.initial``."""
        cfg = self.config
        source = embed_z0(problem.points)
        pose = problem.initial
        for voxel in cfg.voxel_sizes:
            vm = _voxel_map(problem.map, voxel, cfg.max_points_per_voxel, cfg.map_spacing)
            t = self._registration.align_points_to_map(
                source, vm, pose_to_matrix(pose, 4),
                max_correspondance_distance=cfg.gate_factor * voxel, kernel=cfg.kernel_factor * voxel)
            pose = matrix_to_pose(t)
        d = self._distances(problem, pose)
        inliers = float(np.mean(d <= min(cfg.voxel_sizes)))
        return Estimate(pose, inliers >= cfg.min_inlier_fraction, iterations=len(cfg.voxel_sizes),
                        info={"inlier_fraction": inliers})

    def _distances(self, problem: Problem, pose: Pose) -> np.ndarray:
        geom = map_geometry(problem.map, self.config.map_spacing)
        return geom.tree.query(pose.transform(problem.points))[0]

    def score(self, problem: Problem, pose: Pose) -> float:
        """Mean Geman–McClure point-to-point cost of the scan at ``pose`` (dimensionless, lower is better)."""
        voxel = min(self.config.voxel_sizes)
        kernel = self.config.kernel_factor * voxel
        d = self._distances(problem, pose)
        cost = np.where(d <= voxel, d**2 / (kernel + d**2), 1.0)
        return float(np.mean(cost))


REGISTRY = {"kiss-icp": {"class": "KissIcpMatcher", "docs": "baselines/kiss-icp.md", "summary": (
    "KISS-ICP `Registration.align_points_to_map` on a `VoxelHashMap`, voxel schedule 2 → 0.1 "
    "m")}}
