# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/amcl_node.cpp`` (``AmclNode``; ``include/nav2_amcl/amcl_node.hpp``):
``amcl``, Nav2's AMCL ported to numba and run as a tracker, scan by scan.

What runs is Nav2's filter as ``AmclNode`` drives it; this module is the node: the parameters
(Nav2's names and defaults, so ``--param`` reads like a Nav2 YAML), the update gate
``shouldUpdateFilter``, initialisation (``handleInitialPose``, global localization: particles
uniform over free cells), the published pose = the heaviest cluster's mean; the filter, maps,
motion and laser models are the package's other modules, one per Nav2 source file
(``pf/pf.py`` ↔ ``pf/pf.c``, …). Units: metres, radians, seconds.

Why a port: the ``amcl`` wheel (``amcl-wheel``, the fidelity reference) compiles only the beam
model, cannot set ``pf_err``/``pf_z``, publishes the whole set's mean, has no global
initialisation and draws injected poses from ``std::random_device``. Here every draw comes from
one ``drand48`` stream per filter, reseeded with ``seed + i`` at the i-th (re)initialisation (as
``pf_pdf_gaussian_alloc`` reseeds with a counter): a run repeats bit for bit.

Around the filter, as ``amcl-wheel`` and with its code (:mod:`tfloc.baselines._amcl_common`): a
vector map is rasterised at 5 cm, a grid used as given; the odometry increments are integrated
into an odometry pose; between filter updates the estimate is the last published one carried by
the odometry (Nav2's map→odom transform); a start or ``reset`` pose is composed with the odometry
up to the next scan (``handleInitialPose``).
Departures (each a line in the code) and measurements: ``docs/baselines/amcl.md``. A translation
of nav2_amcl's LGPL-2.1-or-later code, as is every module of the package (licence note in the docs).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate
from tfloc.core.tracker import GLOBAL_START, START_KEY
from tfloc.core.traits import Confidence
from tfloc.errors import InvalidProblemError
from tfloc.maps.cache import cached

from .._amcl_common import ScanLimits, amcl_grid, carry, resolve_config
from .angleutils import angle_diff
from .map.map import NavMap, nav_map
from .map.map_cspace import occ_dist
from .motion_model.differential_motion_model import differential
from .motion_model.omni_motion_model import omni
from .pf import pf
from .pf.pf_pdf import new_stream
from .sensors.laser.beam_model import beam_model
from .sensors.laser.laser import beam_step
from .sensors.laser.likelihood_field_model import likelihood_field, likelihood_table

DIFFERENTIAL = ("differential", "nav2_amcl::DifferentialMotionModel")
OMNI = ("omni", "nav2_amcl::OmniMotionModel")


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`AmclTracker`: Nav2's names and defaults (``amcl_node.cpp``), then
    tfloc's own (``global_localization``, the initial spread, ``seed``); metres, radians."""

    RULES: ClassVar[dict] = {
        ">= 1": ("min_particles", "max_particles", "resample_interval"),
        ">= 0": ("alpha1", "alpha2", "alpha3", "alpha4", "alpha5", "pf_z", "z_hit", "z_short", "z_max",
                 "z_rand", "lambda_short", "update_min_d", "update_min_a", "initial_sigma_xy",
                 "initial_sigma_theta", "seed"),
        "> 0": ("pf_err", "sigma_hit", "laser_likelihood_max_dist"),
        "[0, 1]": ("recovery_alpha_slow", "recovery_alpha_fast"),
        "finite": ("laser_max_range", "laser_min_range"),
        DIFFERENTIAL + OMNI: ("robot_model_type",),
        ("likelihood_field", "beam"): ("laser_model_type",),
    }

    min_particles: int = 500  #: KLD sampling's fewest particles
    max_particles: int = 2000  #: KLD sampling's most particles (and the initial count)
    pf_err: float = 0.05  #: KLD bound: largest error between true and sampled distribution
    pf_z: float = 0.99  #: KLD bound: the normal quantile z (Nav2 passes 0.99 where pf.c's default is 3)
    recovery_alpha_slow: float = 0.0  #: slow average's decay for random particles (0: off)
    recovery_alpha_fast: float = 0.0  #: fast average's decay for random particles (0: off)
    resample_interval: int = 1  #: filter updates per resampling
    alpha1: float = 0.2  #: odometry noise: rotation from rotation
    alpha2: float = 0.2  #: odometry noise: rotation from translation
    alpha3: float = 0.2  #: odometry noise: translation from translation
    alpha4: float = 0.2  #: odometry noise: translation from rotation
    alpha5: float = 0.2  #: odometry noise: strafe (omni only)
    robot_model_type: str = "differential"  #: motion model (differential or omni; Nav2's plugin names too)
    laser_model_type: str = "likelihood_field"  #: sensor model: likelihood_field or beam
    laser_likelihood_max_dist: float = 2.0  #: likelihood field: distances capped here (metres)
    max_beams: int = 60  #: beams used per update (every (n − 1) / (max_beams − 1)-th)
    z_hit: float = 0.5  #: weight of the hit part
    z_short: float = 0.05  #: beam model: weight of the short part
    z_max: float = 0.05  #: beam model: weight of the max-range part
    z_rand: float = 0.5  #: weight of the random part
    sigma_hit: float = 0.2  #: sd of the hit part (metres)
    lambda_short: float = 0.1  #: beam model: decay of the short part (1/m)
    laser_max_range: float = 100.0  #: range cap (metres; ≤ 0: the laser's)
    laser_min_range: float = -1.0  #: ranges at or below become the cap (metres; ≤ 0: none)
    update_min_d: float = 0.25  #: update after moving this far along x or y (metres)
    update_min_a: float = 0.2  #: ... or turning this far (radians)
    global_localization: bool = False  #: start uniform over free cells, ignoring the start pose
    initial_sigma_xy: float = 0.0  #: sd of the initial particles in x and y (metres)
    initial_sigma_theta: float = 0.0  #: sd of their heading (radians)
    seed: int = 0  #: seed of the filter's drand48 stream


class AmclTracker:
    """Nav2's AMCL as a :class:`~tfloc.core.tracker.Tracker` (no single-scan mode). See the module
    docstring and ``docs/baselines/amcl.md``. For reports, untimed and read-only: :meth:`belief`
    (the weighed particles), :meth:`likelihood` (the laser model's factor at any pose) and
    :meth:`last_motion`; with ``global_localization`` the first step's ``info["start"]`` is
    ``"global"`` (the start pose the harness passed was ignored)."""

    name = "amcl"
    METHOD = "nav2-amcl"  # (tfloc.core.traits)
    CONFIDENCE = Confidence("sigma_xy_m", False, "the particles' position spread (metres)")

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        self.config = resolve_config(Config, config, overrides)
        self._nav: NavMap | None = None
        self._weighed = self._scan_used = self._motion = None  # what the accessors read (start resets them)
        self.reproducible = True  #: runs with the same seed repeat bit for bit

    # -- the Tracker protocol ------------------------------------------------------------------
    def warm(self, map: Map, laser: LaserSpec, ranges: np.ndarray, pose: Pose) -> None:
        """Untimed: the map's structures (grid, distance field, tables, all cached per map) and the
        compiled kernels, by a start and two updates (one with motion) of a throwaway filter."""
        probe = AmclTracker(self.config)
        probe.start(map, laser, pose)
        probe.step(ranges, Pose(), 0.0)
        probe.step(ranges, Pose(1.0, 0.0, 0.5), 0.1)

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        """Prepare the filter on ``map``. The particles are drawn around ``pose`` (carried by the
        first step's odometry) at the first step, or, with ``global_localization``, uniformly over
        the free cells now (``pose`` ignored)."""
        c = self.config
        if not c.global_localization and not pose.is_finite():
            raise InvalidProblemError(f"amcl: starting pose is not finite: {pose}")
        grid = amcl_grid(map)
        nav = nav_map(grid)
        drawn = c.global_localization or c.recovery_alpha_slow > 0 or c.recovery_alpha_fast > 0
        if drawn and nav.free_cells.size == 0:
            raise InvalidProblemError(f"amcl: {grid.name} has no free cell to draw random poses from")
        self._limits = ScanLimits.of(laser, c.laser_max_range, c.laser_min_range)
        self._range_max = self._limits.range_max
        self._bearings = np.ascontiguousarray(laser.angles, dtype=float)
        self._step = beam_step(self._bearings.size, c.max_beams)
        if c.laser_model_type == "likelihood_field":
            key = ("amcl-likelihood", c.laser_likelihood_max_dist, c.z_hit, c.z_rand, c.sigma_hit, self._range_max)
            self._table, self._off_map = cached(grid, key, lambda: likelihood_table(
                occ_dist(grid, c.laser_likelihood_max_dist), c.z_hit, c.z_rand, c.sigma_hit,
                self._range_max, c.laser_likelihood_max_dist))
        self._nav = nav
        self._odom = Pose()
        self._inits = 0
        self._w_slow = self._w_fast = 0.0
        self._pf_init = False          # Nav2's pf_init_: the first scan since (re)initialisation came
        self._pf_odom = np.zeros(3)    # odometry pose at the last filter update
        self._resample_count = 0
        self._first_pose_sent = False
        self._est, self._est_odom = pose, self._odom  # last published pose and its odometry
        self._pending: tuple[Pose, Pose] | None = None
        self.updates = 0
        self._weighed: tuple[np.ndarray, np.ndarray] | None = None  # for belief(): the last weighed set
        self._scan_used: np.ndarray | None = None                      # ... and its scan (likelihood())
        self._motion: tuple[np.ndarray, np.ndarray, Pose] | None = None  # ... and its motion (last_motion())
        self._say_global = c.global_localization  # the first step's info says the start pose was ignored
        if c.global_localization:  # Nav2's reinitialize_global_localization
            self._rng = self._stream()
            self._set = pf.init_uniform(self._rng, nav.free_cells, nav.geometry, c.max_particles)
            k = self._set.heaviest()  # no scan yet: the prior's heaviest cluster stands for the pose
            self._est = Pose.from_array(self._set.cluster_mean[k]) if k >= 0 else Pose()
        else:
            self._pending = (pose, self._odom)

    def predict(self, odom_delta: Pose) -> Pose:
        """The pose the next step starts from: the last estimate carried by the odometry."""
        if self._nav is None:
            raise RuntimeError("AmclTracker.predict before start")
        pose, at = self._pending or (self._est, self._est_odom)
        return carry(pose, at, self._odom.compose(odom_delta))

    def reset(self, pose: Pose) -> None:
        """Put the belief at ``pose`` (the current scan's): the particles are drawn around it at
        the next step, carried by its odometry (Nav2's initial-pose message)."""
        if self._nav is None:
            raise RuntimeError("AmclTracker.reset before start")
        self._pending = (pose, self._odom)
        self._est, self._est_odom = pose, self._odom

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        """One scan, as ``AmclNode::laserReceived``: integrate the odometry; the first scan after
        an initialisation updates the filter without motion, later ones when the odometry moved
        more than ``update_min_d`` along x or y or turned more than ``update_min_a``; publish the
        heaviest cluster's mean after a resampling; otherwise carry the last one by the odometry."""
        if self._nav is None:
            raise RuntimeError("AmclTracker.step before start")
        c = self.config
        scan = self._limits.apply(ranges, where)
        self._odom = self._odom.compose(odom_delta)
        pose = np.array([self._odom.x, self._odom.y, self._odom.theta])
        if self._pending is not None:
            self._initialise(*self._pending)
        force = resampled = published = False
        injected = 0
        if not self._pf_init:
            self._pf_odom, self._pf_init, self._resample_count = pose, True, 0
            update = force = True
        else:
            delta = np.array([pose[0] - self._pf_odom[0], pose[1] - self._pf_odom[1],
                              angle_diff(pose[2], self._pf_odom[2])])
            update = bool(abs(delta[0]) > c.update_min_d or abs(delta[1]) > c.update_min_d
                          or abs(delta[2]) > c.update_min_a)
            if update:
                self._move(pose, delta)
        if update:
            self._sense(scan)
            self._pf_odom = pose
            self.updates += 1
            self._resample_count += 1
            if self._resample_count % c.resample_interval == 0:
                self._set, self._w_slow, self._w_fast, injected = pf.resample(
                    self._rng, self._set, self._w_slow, self._w_fast, c.min_particles, c.max_particles,
                    c.pf_err, c.pf_z, self._nav.free_cells, self._nav.geometry)
                resampled = True
        s = self._set
        k = s.heaviest()
        if (resampled or force or not self._first_pose_sent) and k >= 0:
            self._est, self._est_odom = Pose.from_array(s.cluster_mean[k]), self._odom
            self._first_pose_sent = published = True
        est = self._est if published else carry(self._est, self._est_odom, self._odom)
        info = {"updated": update, "resampled": resampled, "particles": s.count,
                "clusters": int(s.cluster_weight.size), "bins": s.bins,
                "cluster_weight": float(s.cluster_weight[k]) if k >= 0 else 0.0,
                "cov_trace": float(np.trace(s.cov)),
                "cluster_cov_trace": float(np.trace(s.cluster_cov[k])) if k >= 0 else None,
                "sigma_xy_m": float(math.sqrt(max(s.cov[0, 0] + s.cov[1, 1], 0.0))),
                "sigma_theta_rad": float(math.sqrt(max(s.cov[2, 2], 0.0))), "injected": injected}
        if self._say_global:  # the harness passed the first row's pose; a global start ignored it
            info[START_KEY] = GLOBAL_START
            self._say_global = False
        return Estimate(est, bool(s.converged), 1 if update else 0, s.count if update else 0, info)

    # -- what the filter believes: read-only accessors for reports (untimed, no state change) ----
    def belief(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The particles ``(N, 3)`` (metres, radians, headings unwrapped) and their normalised
        weights ``(N,)`` as the last sensor update weighed them, before it resampled; ``None``
        before the first update. Copies: what a picture of the belief draws."""
        if self._weighed is None:
            return None
        poses, weights = self._weighed
        return poses.copy(), weights.copy()

    def likelihood(self, poses: np.ndarray) -> np.ndarray:
        """The laser model's factor ``p = 1 + Σ pz³`` for the last weighed scan at each of
        ``poses`` ``(M, 3)``: what a particle there was or would have been multiplied by (the
        weights of :meth:`belief` are these, normalised, when the set's weights were uniform)."""
        if self._scan_used is None:
            raise RuntimeError("AmclTracker.likelihood before the first filter update")
        poses = np.ascontiguousarray(np.asarray(poses, dtype=float).reshape(-1, 3))
        factors = np.ones(poses.shape[0])
        self._model(poses, factors, self._scan_used)
        return factors

    def last_motion(self) -> tuple[np.ndarray, np.ndarray, Pose] | None:
        """The last motion update: the particles before and after it (``(N, 3)`` each, the same
        order) and the odometry increment it applied (robot frame at the previous update); the
        noise the model added is each particle's pose after minus before ⊕ increment. ``None``
        before the first update with motion."""
        if self._motion is None:
            return None
        before, after, delta = self._motion
        return before.copy(), after.copy(), delta

    # -- the filter ------------------------------------------------------------------------------
    def _stream(self) -> np.ndarray:
        """The drand48 stream of the next (re)initialisation: ``seed + i`` (low 32 bits)."""
        rng = new_stream((self.config.seed + self._inits) & 0xFFFFFFFF)
        self._inits += 1
        return rng

    def _initialise(self, pose: Pose, at: Pose) -> None:
        """``handleInitialPose``: ``pf_init`` around ``pose`` carried by the odometry since ``at``,
        covariance diag(σxy², σxy², σθ²)."""
        c = self.config
        p = carry(pose, at, self._odom)
        cov = np.diag([c.initial_sigma_xy ** 2, c.initial_sigma_xy ** 2, c.initial_sigma_theta ** 2])
        self._rng = self._stream()
        self._set = pf.init_gaussian(self._rng, p.as_array(), cov, c.max_particles)
        self._w_slow = self._w_fast = 0.0
        self._pf_init, self._pending = False, None
        self._est, self._est_odom = p, self._odom

    def _move(self, pose: np.ndarray, delta: np.ndarray) -> None:
        """The motion model's ``odometryUpdate`` on a copy of the particles."""
        c = self.config
        poses = self._set.poses.copy()
        if c.robot_model_type in OMNI:
            omni(self._rng, poses, pose, delta, c.alpha1, c.alpha2, c.alpha3, c.alpha4, c.alpha5)
        else:
            differential(self._rng, poses, pose, delta, c.alpha1, c.alpha2, c.alpha3, c.alpha4)
        self._motion = (self._set.poses, poses, Pose.from_array(self._pf_odom).between(Pose.from_array(pose)))
        self._set = dataclasses.replace(self._set, poses=poses)

    def _sense(self, scan: np.ndarray) -> None:
        """``pf_update_sensor`` with the configured laser model, on a copy of the weights."""
        c, s = self.config, self._set
        weights = s.weights.copy()
        total = self._model(s.poses, weights, scan)
        self._w_slow, self._w_fast = pf.normalise(weights, total, self._w_slow, self._w_fast,
                                                  c.recovery_alpha_slow, c.recovery_alpha_fast)
        self._set = dataclasses.replace(s, weights=weights)
        self._weighed, self._scan_used = (s.poses, weights), scan

    def _model(self, poses: np.ndarray, weights: np.ndarray, scan: np.ndarray) -> float:
        """The configured laser model: ``weights`` multiplied in place by each pose's factor; their sum."""
        c, nav = self.config, self._nav
        if c.laser_model_type == "beam":
            return beam_model(poses, weights, scan, self._bearings, self._step, self._range_max,
                                     nav.occ_state, *nav.geometry, c.z_hit, c.z_short, c.z_max, c.z_rand,
                                     c.sigma_hit, c.lambda_short)
        return likelihood_field(poses, weights, scan, self._bearings, self._step,
                                       self._range_max, self._table, self._off_map, *nav.geometry)


REGISTRY = {"amcl": {"class": "AmclTracker", "docs": "baselines/amcl.md", "files": ["baselines/amcl/", "baselines/_amcl_common.py"], "summary": (
    "a **tracker** (sequence datasets only, no single-scan mode): a numba port of Nav2's AMCL"
    " (`nav2_amcl`: KLD-sampling, recovery injection, the heaviest cluster's mean, the "
    "differential motion model, the likelihood-field and beam models, Nav2's update gate, "
    "global initialisation), Nav2's parameter names and defaults; fidelity tested against the"
    " `amcl` wheel ([docs/baselines/amcl.md](baselines/amcl.md)); licence LGPL-2.1-or-later "
    "(a translation of nav2_amcl; a module per `nav2_amcl` source file)")}}
