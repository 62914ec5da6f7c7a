"""``kiss-icp``: KISS-ICP's own registration of the real scan against a voxel map of the map.

Inputs are the map, the laser spec, the real scan and the initial pose (never the truth). It calls
``kiss_icp.registration.Registration.align_points_to_map`` with a ``kiss_icp.mapping.VoxelHashMap``
filled with the map's geometry; KISS-ICP's internals are not rewritten. Configuration choices and
why (the strongest honest setup we found for this method):

* **Scan embedded at z = 0**, all valid beams, no KISS-ICP preprocessing (no deskewing, no
  voxel downsampling of 181 points: every point helps on a single 2D scan).
* **Target = the map's sampled geometry** (``map.sample_points`` every ``map_spacing`` = 2 cm)
  in one ``VoxelHashMap`` per voxel size, built once per map and cached. Cropping around the initial
  pose is unnecessary here: KISS-ICP's correspondence search only visits the 27 voxels around each
  transformed scan point, so distant map points are never touched.
  ``max_points_per_voxel`` is KISS-ICP's default (20); its insertion keeps points at least
  ``voxel / sqrt(20)`` apart, which still leaves ~2 cm detail at the finest voxel.
* **Voxel schedule** ``voxel_sizes`` = 2.0 → 1.0 → 0.3 → 0.1 m. KISS-ICP's default voxel size
  here (max_range / 100 = 0.1 m) only converges from about 0.2 m, because the neighbour-voxel
  search makes the voxel size the effective correspondence gate. Each stage starts from the last
  result.
* Per stage, ``max_correspondance_distance`` = ``gate_factor`` × voxel (3, i.e. no cut beyond
  what the neighbour-voxel search already reaches) and the Geman–McClure ``kernel`` =
  ``kernel_factor`` × voxel (1).
  On the quick test-room check (90 problems, 0–3 m / 0–15°; a script of the first session, since replaced by
  the harness's run configurations):
  voxels 1.0 → 0.3 → 0.1 with kernel voxel/3 succeeded on 56 %, with kernel = voxel on 66 %,
  with kernel voxel/10 on 50 %; a 2 m first voxel with kernel = voxel on 69 %, a 3 m one on 71 %
  (one or two problems more: noise at this size, so the 2 m stage that matches ``o3d-icp``'s
  first gate is kept). A gate of 1 × voxel instead of 3 × changed nothing (56 %).
* KISS-ICP's defaults for ``max_num_iterations`` (500) and ``convergence_criterion`` (1e-4);
  ``max_num_threads`` = 1 because the harness already runs one worker per core.
* The 6-DoF result is **projected onto SE(2)** after every stage.
* ``converged`` = at least ``min_inlier_fraction`` (0.5) of the scan points lie within the last
  voxel size of a map point at the result; a self-check, not a claim of correctness.

**Amortised per map** (``prepare``): the map's 2 cm samples with their KD-tree (for the inlier
check and ``score``) and one ``VoxelHashMap`` per voxel size. **Per scan**: only KISS-ICP's
registration against those voxel maps and the inlier check.

``score(problem, pose)`` is KISS-ICP's own objective at ``pose``: the mean Geman–McClure cost
``r² / (κ + r²)`` of the point-to-point distance ``r`` from each scan point to its nearest map
sample, with KISS-ICP's last-stage kernel κ; a point with no sample within the last voxel counts
as 1.
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
