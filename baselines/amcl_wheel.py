"""``amcl-wheel``: AMCL (Nav2's adaptive Monte Carlo localization) as a tracker, through the ``amcl``
wheel: the fidelity reference of the ``amcl`` port (:mod:`tfloc.baselines.amcl`).

The ``amcl`` 0.1.2 wheel on PyPI ("AMCL Python Bindings", GPL-3.0, nanobind) compiles Nav2's
``nav2_amcl`` particle filter (``pf.c``, KLD sampling, the differential/omni motion models, the
*beam* sensor model, ``map_calc_range``) behind a small API: ``AMCL(min_particles, max_particles,
alpha_slow, alpha_fast, MotionParameters(α1…α5), LaserParameters(z_hit, z_short, z_max, z_rand,
sigma_hit, lambda_short, chi_outlier, max_beams), robot_model_type)``, ``set_map``,
``set_laser_pose``, ``set_initial_pose(pose, cov)``, ``update(scan, odom_pose)`` and
``get_pose_mean``/``get_pose_covariance``. This module does what Nav2's ``amcl_node`` does around
the filter; the wheel's departures from Nav2 (``docs/baselines/amcl-wheel.md``), in short:

* **The sensor model is the beam model**: the wheel builds ``BeamModel`` in ``set_map`` whatever
  the parameters; it has no likelihood field (no ``laser_likelihood_max_dist``, no distance map).
  Nav2's default is ``likelihood_field``, so this is AMCL with ``laser_model_type: beam``.
* ``update`` always moves, weighs and resamples; Nav2's update gate (``update_min_d`` /
  ``update_min_a``, per odometry axis, as ``AmclNode::shouldUpdateFilter``) is applied here, and
  between updates the estimate is the last one carried by the odometry (Nav2's map→odom transform).
* The KLD bound uses pf.c's own ``pop_err`` 0.01 / ``pop_z`` 3 (Nav2 sets 0.05 / 0.99); the wheel
  does not expose them. It reports the whole particle set's mean, not the heaviest cluster's.
* Random numbers: the filter draws from the C library's ``drand48``; ``pf_alloc`` seeds it with
  the clock and ``set_initial_pose`` with a process-wide counter. Here the counter is set to
  ``seed`` before the initial draw (for the one build whose machine code we read) and
  ``srand48(seed)`` after it.
* No global localization; random particle injection draws from an unseeded ``std::mt19937``:
  such runs do not repeat.

A vector map is rasterised at 5 cm, a grid map used as it is, both handed over in map_server's
trinary form (occupied 100, free 0, unknown -1); the grid, the scan's limits and the pose carried
by the odometry are the port's code too (:mod:`tfloc.baselines._amcl_common`).
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.pose import Pose, wrap_angle
from tfloc.core.problem import Estimate
from tfloc.core.traits import Confidence
from tfloc.errors import InvalidProblemError, ParameterError
from tfloc.maps.cache import cached
from tfloc.maps.grid import GridMap

from ._amcl_common import ScanLimits, amcl_grid, carry, resolve_config

try:
    import amcl as _amcl
    import amcl._amcl_impl as _amcl_impl
except ImportError as _exc:  # one line saying why, reported by tfloc.get_matcher
    raise ImportError("amcl (AMCL Python bindings, GPL-3.0) is not installed (pip install 'tfloc[amcl]')",
                      name="amcl") from _exc

_libc = ctypes.CDLL(None)  # the process's C library: the wheel draws from its drand48 stream


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`AmclTracker`: Nav2's names and defaults (``nav2_amcl/src/amcl_node.cpp``)
    where the wheel has them; metres, radians, seconds."""

    RULES: ClassVar[dict] = {
        ">= 1": ("min_particles", "max_particles"),
        ">= 0": ("alpha1", "alpha2", "alpha3", "alpha4", "alpha5", "z_hit", "z_short", "z_max",
                 "z_rand", "lambda_short", "update_min_d", "update_min_a", "initial_sigma_xy",
                 "initial_sigma_theta", "seed"),
        "> 0": ("sigma_hit",),
        "[0, 1]": ("recovery_alpha_slow", "recovery_alpha_fast"),
        "finite": ("laser_max_range", "laser_min_range"),
        ("differential", "omni"): ("robot_model_type",),
    }

    min_particles: int = 500  #: KLD sampling's fewest particles
    max_particles: int = 2000  #: KLD sampling's most particles
    recovery_alpha_slow: float = 0.0  #: slow average's decay for random particles (0: off)
    recovery_alpha_fast: float = 0.0  #: fast average's decay for random particles (0: off)
    alpha1: float = 0.2  #: odometry noise: rotation from rotation
    alpha2: float = 0.2  #: odometry noise: rotation from translation
    alpha3: float = 0.2  #: odometry noise: translation from translation
    alpha4: float = 0.2  #: odometry noise: translation from rotation
    alpha5: float = 0.2  #: odometry noise: strafe (omni model only)
    robot_model_type: str = "differential"  #: motion model, differential or omni
    laser_model_type: str = "beam"  #: sensor model: only beam (the wheel's one)
    max_beams: int = 60  #: beams used per update
    z_hit: float = 0.5  #: beam model: weight of the hit part
    z_short: float = 0.05  #: beam model: weight of the short part
    z_max: float = 0.05  #: beam model: weight of the max-range part
    z_rand: float = 0.5  #: beam model: weight of the random part
    sigma_hit: float = 0.2  #: beam model: sd of the hit part (metres)
    lambda_short: float = 0.1  #: beam model: decay of the short part (1/m)
    laser_max_range: float = 100.0  #: range cap (metres; ≤ 0: the laser's)
    laser_min_range: float = -1.0  #: ranges at or below become the cap (metres; ≤ 0: none)
    update_min_d: float = 0.25  #: update after moving this far along x or y (metres)
    update_min_a: float = 0.2  #: ... or turning this far (radians)
    initial_sigma_xy: float = 0.0  #: sd of the initial particles in x and y (metres)
    initial_sigma_theta: float = 0.0  #: sd of their heading (radians)
    seed: int = 0  #: seed of the filter's random numbers


#: Builds of the wheel whose pf_pdf seed counter we know: sha256 of ``_amcl_impl*.so`` →
#: (offset of ``PyInit__amcl_impl``, offset of the counter), read from its machine code
_KNOWN_BUILDS = {"d4e3b1f9881a64bb08ecfc30d2019d925fa52208ad61860ffe791bbc38b59e72": (0x18BBF, 0x43FC8)}


@functools.cache
def _pdf_seed_counter() -> ctypes.c_int | None:
    """The wheel's ``pf_pdf_gaussian_alloc`` seed counter (``srand48(++counter)`` before it draws
    the initial particles; process-wide, so a spread start would depend on how many filters the
    process built before), or None for a build we do not know (then only a zero-covariance start,
    the default, is reproducible: ``AmclWheelTracker.reproducible``)."""
    path = Path(_amcl_impl.__file__)
    known = _KNOWN_BUILDS.get(hashlib.sha256(path.read_bytes()).hexdigest())
    if known is None:
        return None
    lib = ctypes.CDLL(str(path))  # the loaded module itself (dlopen returns the same handle)
    base = ctypes.cast(lib.PyInit__amcl_impl, ctypes.c_void_p).value - known[0]
    return ctypes.c_int.from_address(base + known[1])


def _occupancy_grid(grid: GridMap):  # noqa: ANN202 - an amcl.OccupancyGrid
    """``grid`` as map_server's trinary OccupancyGrid (row-major from the origin corner, as ROS)."""
    data = np.full(grid.shape, -1, dtype=np.int8)
    data[grid.free] = 0
    data[grid.occupied] = 100
    H, W = grid.shape
    out = _amcl.OccupancyGrid(W, H, grid.resolution, grid.origin[0], grid.origin[1])
    out.data = data.ravel()
    return out


def _vec(p: Pose):  # noqa: ANN202 - an amcl.Vector3D
    return _amcl.Vector3D(float(p.x), float(p.y), float(p.theta))


class AmclWheelTracker:
    """Nav2's AMCL run scan by scan (the :class:`~tfloc.core.tracker.Tracker` protocol); no
    single-scan mode (no ``localize``). See the module docstring and ``docs/baselines/amcl-wheel.md``."""

    name = "amcl-wheel"
    METHOD = "nav2-amcl"  # (tfloc.core.traits)
    CONFIDENCE = Confidence("sigma_xy_m", False, "the filter's position standard deviation (metres)")

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        self.config = c = resolve_config(Config, config, overrides)
        if c.laser_model_type != "beam":
            raise ParameterError(f"laser_model_type must be 'beam', got {c.laser_model_type!r}: the amcl wheel "
                                 "compiles only AMCL's beam model (no likelihood field)", ("laser_model_type",))
        if c.z_hit + c.z_short + c.z_max + c.z_rand <= 0:
            raise ParameterError("z_hit + z_short + z_max + z_rand must be > 0",
                                 ("z_hit", "z_short", "z_max", "z_rand"))
        self._filter = None

    # -- the Tracker protocol ------------------------------------------------------------------
    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        """Build the filter on ``map`` (grid as given, vector map rasterised at 5 cm); the particles
        are drawn around ``pose`` (carried by the first step's odometry) at the first step, Nav2's
        ``set_initial_pose``, covariance from ``initial_sigma_*`` (zero by default, as Nav2 with
        its ``initial_pose`` parameters)."""
        if not pose.is_finite():
            raise InvalidProblemError(f"amcl: starting pose is not finite: {pose}")
        c = self.config
        grid = amcl_grid(map)
        occ = cached(grid, "amcl-occupancy-grid", lambda: _occupancy_grid(grid))
        f = _amcl.AMCL(c.min_particles, c.max_particles, c.recovery_alpha_slow, c.recovery_alpha_fast,
                       _amcl.MotionParameters(c.alpha1, c.alpha2, c.alpha3, c.alpha4, c.alpha5),
                       _amcl.LaserParameters(c.z_hit, c.z_short, c.z_max, c.z_rand, c.sigma_hit,
                                             c.lambda_short, 0.0,  # chi_outlier 0: as Nav2
                                             min(c.max_beams, laser.n_beams)),  # more would step by 0: a hang
                       c.robot_model_type)
        f.set_map(occ)
        f.set_laser_pose(_amcl.Vector3D(0.0, 0.0, 0.0))
        self._filter = f
        self._limits = ScanLimits.of(laser, c.laser_max_range, c.laser_min_range)
        self._bearings = np.asarray(laser.angles, dtype=float)
        self._odom = Pose(0.0, 0.0, 0.0)          # the integrated odometry (its own frame)
        self._odom_at_update: Pose | None = None  # odometry at the last filter update
        self._pose_at_update = pose               # the filter's estimate at the last update
        self._init_at: tuple[Pose, Pose] | None = (pose, self._odom)  # (pose, odometry) to start from
        self._inits = 0
        self.updates = 0
        #: whether runs repeat bit for bit: not with random injection (std::random_device), nor a
        #: spread start on a build whose seed counter we do not know
        self.reproducible = c.recovery_alpha_slow == 0 and c.recovery_alpha_fast == 0 and (
            _pdf_seed_counter() is not None or (c.initial_sigma_xy == 0 and c.initial_sigma_theta == 0))

    def reset(self, pose: Pose) -> None:
        """Start the filter again at ``pose`` (the current scan's), as Nav2 does on an initial-pose
        message; the particles are drawn at the next step, carried by its odometry."""
        if self._filter is None:
            raise RuntimeError("AmclWheelTracker.reset before start")
        self._init_at, self._odom_at_update, self._pose_at_update = (pose, self._odom), None, pose

    def predict(self, odom_delta: Pose) -> Pose:
        """The pose the next step starts from: the last estimate carried by the odometry."""
        if self._filter is None:
            raise RuntimeError("AmclWheelTracker.predict before start")
        pose, at = self._init_at or (self._pose_at_update, self._odom_at_update)
        return carry(pose, at, self._odom.compose(odom_delta))

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        """One scan: integrate the odometry; update the filter when Nav2 would (the first scan,
        then when the odometry moved more than ``update_min_d`` along x or y or ``update_min_a``
        in heading since the last update); otherwise carry the last estimate by the odometry."""
        if self._filter is None:
            raise RuntimeError("AmclWheelTracker.step before start")
        self._odom = self._odom.compose(odom_delta)
        if self._init_at is not None:
            self._initialise(carry(*self._init_at, self._odom))
            self._init_at = None
        update = self._odom_at_update is None or self._moved(self._odom_at_update, self._odom)
        if update:
            self._filter.update(self._scan(ranges, where), _vec(self._odom))
            m = self._filter.get_pose_mean()
            self._pose_at_update = Pose(m.x, m.y, float(wrap_angle(m.theta)))
            self._odom_at_update = self._odom
            self.updates += 1
            pose = self._pose_at_update
        else:
            pose = carry(self._pose_at_update, self._odom_at_update, self._odom)
        cov = np.array(self._filter.get_pose_covariance().to_list())
        info = {"updated": update, "cov_trace": float(np.trace(cov)),
                "sigma_xy_m": float(math.sqrt(max(cov[0, 0] + cov[1, 1], 0.0))),
                "sigma_theta_rad": float(math.sqrt(max(cov[2, 2], 0.0)))}
        return Estimate(pose, True, 1 if update else 0, 0, info)

    def _initialise(self, pose: Pose) -> None:
        """Draw the particles around ``pose`` (the wheel's next update then applies no motion, as
        Nav2's first scan after an initial pose), seeded: ``seed`` for the first start, + 1 for
        each reset."""
        c = self.config
        seed = (c.seed + self._inits) % 2**31
        counter = _pdf_seed_counter()
        if counter is not None:  # set_initial_pose draws the particles after srand48(++counter)
            counter.value = seed
        self._filter.set_initial_pose(_vec(pose), _amcl.create_diagonal_covariance(
            c.initial_sigma_xy ** 2, c.initial_sigma_xy ** 2, c.initial_sigma_theta ** 2))
        _libc.srand48(ctypes.c_long(seed))  # the motion model's and the resampler's draws
        self._inits += 1

    # -- helpers ---------------------------------------------------------------------------------
    def _moved(self, a: Pose, b: Pose) -> bool:
        """Nav2's ``shouldUpdateFilter``: odometry moved along x or y (odometry frame) or turned."""
        c = self.config
        return (abs(b.x - a.x) > c.update_min_d or abs(b.y - a.y) > c.update_min_d
                or abs(float(wrap_angle(b.theta - a.theta))) > c.update_min_a)

    def _scan(self, ranges: np.ndarray, where: str):  # noqa: ANN202 - an amcl.LaserScan
        """The scan as Nav2 hands it to the sensor model (``AmclNode::updateFilter``, the ranges as
        :class:`~tfloc.baselines._amcl_common.ScanLimits` leaves them): ``[range, bearing]`` pairs."""
        r = self._limits.apply(ranges, where)
        scan = _amcl.LaserScan(r.size, self._limits.range_max)
        scan.ranges = np.column_stack((r, self._bearings)).tolist()
        return scan


REGISTRY = {"amcl-wheel": {"class": "AmclWheelTracker", "docs": "baselines/amcl-wheel.md", "files": ["baselines/_amcl_common.py"], "summary": (
    "a **tracker**: Nav2's AMCL through the `amcl` wheel (Python bindings of `nav2_amcl`, "
    "beam model only), the port's fidelity reference; licence GPL-3.0; optional: `pip install"
    " 'tfloc[amcl]'`")}}
