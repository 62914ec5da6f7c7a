"""``o3d-icp``: open3d point-to-line ICP of the real scan against the map, coarse to fine.

Inputs are the map, the laser spec, the real scan and the initial pose (never the truth). Choices
and why (the detail and the measurements: ``docs/baselines/o3d-icp.md``):

* **Scan at z = 0; target = the map's samples** (:func:`tfloc.maps.cache.map_geometry`) within the
  laser's range plus ``crop_margin`` of the initial pose: the margin covers the protocol's
  offsets, so no true partner of a scan point is cropped away.
* **Point-to-line** through ``TransformationEstimationPointToPlane`` with the map's in-plane
  normals: open3d's ``estimate_normals`` gives (0, 0, ±1) on z = 0 points, for which ICP silently
  returns the identity; with (nx, ny, 0) only x, y and yaw enter the residual.
* **Coarse-to-fine gates** (``gates``), each stage from the last result: one small gate finds no
  partners at large offsets, one large gate pairs points with the wrong wall near convergence.
  **Projected onto SE(2) after every stage** (in-plane normals leave z, roll and pitch free).
* ``converged`` = open3d's final fitness ≥ ``min_fitness``: a self-check, not a claim of correctness.

**Amortised per map** (``prepare``): the map's samples, their normals and a KD-tree. **Per scan**:
the crop (a ball query on that tree), its open3d cloud, and the KD-tree open3d builds inside every
``registration_icp`` call (one per gate; open3d takes no prebuilt tree).

``score(problem, pose)``: the mean point-to-line residual (metres) of the scan points against their
nearest map samples, each truncated at the last gate (no sample within it: the gate).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tfloc.core.params import Configured
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem
from tfloc.core.traits import Confidence
from tfloc.maps.cache import map_geometry, point_to_line_residuals

from ._geometry import embed_z0, matrix_to_pose, pose_to_matrix
from ._open3d import import_open3d

o3d = import_open3d()
_reg = o3d.pipelines.registration


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`Open3dIcpMatcher` (metres)."""

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("gates", "map_spacing"),
        ">= 0": ("relative_fitness", "relative_rmse", "crop_margin"),
        ">= 1": ("max_iterations",),
        "[0, 1]": ("min_fitness",)}

    gates: tuple[float, ...] = (2.0, 1.0, 0.5, 0.2, 0.1)  #: correspondence gate per stage (metres)
    max_iterations: int = 30  #: open3d's iterations per stage
    relative_fitness: float = 1e-6  #: open3d's stop on the fitness change
    relative_rmse: float = 1e-6  #: open3d's stop on the RMSE change
    map_spacing: float = 0.05  #: sampling of the map's geometry (metres)
    crop_margin: float = 4.0  #: map kept within the laser's range plus this of the guess (metres)
    min_fitness: float = 0.5  #: converged needs this open3d fitness (0–1)


class Open3dIcpMatcher(Configured):
    """open3d point-to-line ICP with a coarse-to-fine gate schedule (see the module docstring)."""

    name = "o3d-icp"
    CONFIDENCE = Confidence("fitness", True, "open3d's ICP fitness (share of points with a correspondence)")
    CONFIG = Config

    def prepare(self, problem: Problem) -> None:
        """Build the map's sampled geometry and its KD-tree (once per map; untimed by the harness)."""
        map_geometry(problem.map, self.config.map_spacing)

    def localize(self, problem: Problem) -> Estimate:
        """Register the real scan to the map near ``problem.initial``."""
        cfg = self.config
        geom = map_geometry(problem.map, cfg.map_spacing)
        tgt_pts, tgt_nrm = geom.near(problem.initial, problem.laser.max_range + cfg.crop_margin)
        if len(tgt_pts) < 3:
            return Estimate(problem.initial, False, info={"status": "no-answer", "reason": "no map near the initial pose"})
        target = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(embed_z0(tgt_pts)))
        target.normals = o3d.utility.Vector3dVector(embed_z0(tgt_nrm))
        source = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(embed_z0(problem.points)))
        criteria = _reg.ICPConvergenceCriteria(relative_fitness=cfg.relative_fitness,
                                               relative_rmse=cfg.relative_rmse,
                                               max_iteration=cfg.max_iterations)
        estimation = _reg.TransformationEstimationPointToPlane()
        pose, result = problem.initial, None
        for gate in cfg.gates:
            result = _reg.registration_icp(source, target, gate, pose_to_matrix(pose, 4), estimation, criteria)
            pose = matrix_to_pose(result.transformation)
        fitness = float(result.fitness)
        return Estimate(pose, fitness >= cfg.min_fitness, iterations=len(cfg.gates),
                        info={"fitness": fitness, "inlier_rmse_m": float(result.inlier_rmse)})

    def score(self, problem: Problem, pose: Pose) -> float:
        """Mean truncated point-to-line residual (metres) of the scan at ``pose``; lower is better."""
        gate = min(self.config.gates)
        geom = map_geometry(problem.map, self.config.map_spacing)
        dist, res = point_to_line_residuals(geom, pose.transform(problem.points))
        return float(np.mean(np.where(dist <= gate, np.minimum(res, gate), gate)))


REGISTRY = {"o3d-icp": {"class": "Open3dIcpMatcher", "docs": "baselines/o3d-icp.md", "summary": (
    "open3d point-to-line ICP, coarse-to-fine gates 2 → 0.1 m")}}
