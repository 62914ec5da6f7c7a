"""``kiss-icp-adaptive``: KISS-ICP along a sequence with its pipeline's adaptive threshold.

KISS-ICP's pipeline (``cpp/kiss_icp/pipeline/KissICP.cpp``; the Python ``kiss_icp/kiss_icp.py``)
gates each scan's ICP by what it has seen: σ = the package's ``AdaptiveThreshold`` (used here
through ``kiss_icp_pybind._AdaptiveThreshold``, unchanged: ``initial_threshold`` 2 m until a
motion is seen, then the RMS of the *model errors* larger than ``min_motion_th`` 0.1 m, a model
error being ‖Δt‖ + 2·``max_range``·sin(Δθ/2) of the prediction⁻¹ · result deviation); the ICP's
correspondence gate is 3σ and its Geman–McClure kernel σ/3 (the C++ pipeline; the installed
Python pipeline passes σ: ``kernel_factor``). One ICP per scan from the prediction.

Around it, as ``kiss-icp`` (:mod:`tfloc.baselines.kiss_icp`): the scan at z = 0 with every
return, the target a ``VoxelHashMap`` of the map's samples (voxel: KISS-ICP's default,
``max_range`` / 100), the result projected onto SE(2). The prediction is the last estimate
composed with the odometry increment (KISS-ICP's own is constant velocity; its authors' wheel
odometry variant, kinematic-icp, feeds the same threshold with the odometry's prediction).
Units: metres, radians. Values and sources: ``docs/baselines/kiss-icp.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from kiss_icp.pybind import kiss_icp_pybind
from kiss_icp.registration import Registration

from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem
from tfloc.core.tracker import ConfiguredTracker
from tfloc.core.traits import Confidence

from ._geometry import embed_z0, matrix_to_pose, pose_to_matrix
from .kiss_icp import _voxel_map


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`KissIcpAdaptiveTracker` (metres; KISS-ICP's names and defaults)."""

    RULES: ClassVar[dict] = {
        "> 0": ("initial_threshold", "gate_factor", "kernel_factor", "map_spacing", "voxel_size", "max_range"),
        ">= 0": ("min_motion_th", "convergence_criterion"),
        ">= 1": ("max_points_per_voxel", "max_num_iterations", "max_num_threads")}

    initial_threshold: float = 2.0  #: adaptive_threshold.initial_threshold (metres)
    min_motion_th: float = 0.1  #: adaptive_threshold.min_motion_th: smaller model errors are not counted (m)
    max_range: float | None = None  #: data.max_range of the model error (metres; None: the laser's range)
    gate_factor: float = 3.0  #: correspondence gate = this × σ
    kernel_factor: float = 1.0 / 3.0  #: Geman–McClure kernel = this × σ
    voxel_size: float | None = None  #: mapping.voxel_size (metres; None: max_range / 100)
    max_points_per_voxel: int = 20  #: mapping.max_points_per_voxel
    max_num_iterations: int = 500  #: registration.max_num_iterations
    convergence_criterion: float = 1e-4  #: registration.convergence_criterion
    max_num_threads: int = 1  #: registration.max_num_threads (one worker per core)
    map_spacing: float = 0.02  #: sampling of the map's geometry (metres)


class _AdaptiveStage:
    """One KISS-ICP registration from the guess at the tracker's current σ (a single-scan matcher
    for :class:`~tfloc.core.tracker.LocalTracker`'s ``answer``)."""

    name = "kiss-icp-adaptive"

    def __init__(self, config: Config) -> None:
        self.config = config
        self.sigma = config.initial_threshold
        self._registration = Registration(max_num_iterations=config.max_num_iterations,
                                          convergence_criterion=config.convergence_criterion,
                                          max_num_threads=config.max_num_threads)

    def voxel(self, problem: Problem) -> float:
        c = self.config
        return c.voxel_size if c.voxel_size is not None else (c.max_range or problem.laser.max_range) / 100.0

    def _map(self, problem: Problem):  # noqa: ANN202 - a kiss_icp VoxelHashMap
        c = self.config
        return _voxel_map(problem.map, self.voxel(problem), c.max_points_per_voxel, c.map_spacing)

    def prepare(self, problem: Problem) -> None:
        self._map(problem)

    def localize(self, problem: Problem) -> Estimate:
        c = self.config
        t = self._registration.align_points_to_map(
            embed_z0(problem.points), self._map(problem), pose_to_matrix(problem.initial, 4),
            max_correspondance_distance=c.gate_factor * self.sigma, kernel=c.kernel_factor * self.sigma)
        return Estimate(matrix_to_pose(t), True, info={"sigma": self.sigma})


class KissIcpAdaptiveTracker(ConfiguredTracker):
    """KISS-ICP with its adaptive threshold along a sequence (see the module docstring)."""

    name = "kiss-icp-adaptive"
    METHOD = "kiss-icp"  # (tfloc.core.traits)
    CONFIDENCE = Confidence("sigma", False, "its adaptive threshold's sigma (metres)")
    CONFIG = Config

    def matcher_of(self, config: Config) -> _AdaptiveStage:
        return _AdaptiveStage(config)

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        super().__init__(config, **overrides)
        self._threshold = None

    def start(self, map, laser, pose: Pose) -> None:  # noqa: ANN001 - the Tracker protocol's
        super().start(map, laser, pose)
        c = self.config
        self._threshold = kiss_icp_pybind._AdaptiveThreshold(
            initial_threshold=c.initial_threshold, min_motion_th=c.min_motion_th,
            max_range=float(c.max_range or laser.max_range))

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        if self._threshold is None:
            raise RuntimeError("KissIcpAdaptiveTracker.step before start")
        pred = self.predict(odom_delta)
        self.matcher.sigma = float(self._threshold._compute_threshold())
        problem, est = self.answer(ranges, pred, where)
        if problem is not None and not est.declined:
            deviation = np.linalg.solve(pose_to_matrix(pred, 4), pose_to_matrix(est.pose, 4))
            self._threshold._update_model_deviation(model_deviation=deviation)
        self.pose = est.pose
        return est


REGISTRY = {"kiss-icp-adaptive": {"class": "KissIcpAdaptiveTracker", "docs": "baselines/kiss-icp.md", "summary": (
    "a **tracker**: KISS-ICP with its pipeline's own adaptive threshold (gate 3σ, kernel "
    "σ/3). Its package's shipped values are the preset `kiss-icp-track`")}}
