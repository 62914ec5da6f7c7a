"""``karto``: OpenKarto's correlative scan matcher (the one behind slam_toolbox), two-stage.

Inputs are the map, the laser spec, the real scan and the initial pose (never the truth). It calls
``karto_scanmatcher.Wrapper.match_scan`` unchanged (``karto-scanmatcher`` 1.0.0: pybind11 bindings of
OpenKarto's ``ScanMatcher``, Python 3.8–3.11; OpenKarto LGPL-3.0, the wheel ships GPL-3.0), which
correlates a scan with other scans, never with a grid. Choices and why (the tuning record, the
wrapper's API and the measurements: ``docs/baselines/karto.md``):

* **The map is handed over as scans** (Karto's documented use): 360° scans from a lattice of free
  positions (:mod:`tfloc.baselines._scan_lattice`), those within ``base_radius`` of the guess. On a
  grid a beam ends in the middle of the occupied run it meets (``base_surface`` = ``run-centre``),
  where a SLAM system's recorded scans would put the surface; the near face is biased short on
  thick walls.
* **Two stages, Karto's loop-closure pattern**: a coarse search over the protocol's window without
  penalties, then Karto's sequential defaults with its penalties (``coarse`` false: the latter
  alone, as slam_toolbox's localization mode matches: preset ``karto-track``).
* ``range_threshold`` = the laser's range (Karto's 40 m default sizes its grids for 40 m);
  ``converged`` = final response ≥ ``min_response``, a self-check.

**Amortised per map** (``prepare``): the lattice and every position's base scan as a Karto scan.
**Per scan**: the query scans and Karto's two correlations (Karto builds its grid from the base
scans for every match; its API keeps no grid between matches).

``score(problem, pose)``: minus Karto's response (mean smeared occupancy under the scan's points)
of a correlation centred at ``pose`` within ``score_window``, at the pose's heading, against the
same base scans.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose, wrap_angle
from tfloc.core.problem import Estimate, Problem
from tfloc.core.traits import Confidence
from tfloc.errors import ParameterError
from tfloc.maps.cache import cached

from ._scan_lattice import ScanLattice, scan_lattice

try:
    import karto_scanmatcher as ksm
except ImportError as _exc:  # one line saying why, reported by tfloc.get_matcher
    raise ImportError(
        "karto-scanmatcher is not installed (pip install 'tfloc[karto]'; it has wheels for Python 3.8-3.11 "
        f"only, this is Python {sys.version_info.major}.{sys.version_info.minor})",
        name="karto_scanmatcher") from _exc


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`KartoMatcher` (metres; degrees where named; Karto's own units otherwise)."""

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params); the windows: _check_window
        "> 0": ("coarse_angle_resolution_deg", "fine_angle_resolution_deg", "lattice_spacing",
                "virtual_beam_deg", "base_radius", "range_threshold"),
        ">= 0": ("coarse_angle_offset_deg", "lattice_clearance", "distance_variance_penalty",
                 "minimum_distance_penalty", "angle_variance_penalty", "minimum_angle_penalty",
                 "min_response"),
        ("run-centre", "near-face"): ("base_surface",)}

    coarse: bool = True  #: run the coarse stage first (false: the sequential matcher alone)
    coarse_search_size: float = 7.0  #: coarse stage: window width (metres: ±3.5 m, the protocol's)
    coarse_resolution: float = 0.1  #: coarse stage: cell (metres)
    coarse_smear_deviation: float = 0.1  #: coarse stage: Karto's smear deviation (metres)
    fine_search_size: float = 0.3  #: fine stage: window width (metres; Karto's sequential default)
    fine_resolution: float = 0.01  #: fine stage: cell (metres; Karto's default)
    fine_smear_deviation: float = 0.03  #: fine stage: smear deviation (metres)
    coarse_angle_offset_deg: float = 20.0  #: angular search ± this, both stages (degrees; Karto's default)
    coarse_angle_resolution_deg: float = 2.0  #: coarse angular step (degrees; Karto's default)
    fine_angle_resolution_deg: float = 0.2  #: fine angular step (degrees; Karto's default)
    use_response_expansion: bool = True  #: Karto's retries over wider angles when nothing responds
    distance_variance_penalty: float = 0.5  #: Karto's default; penalties apply in the fine stage only
    minimum_distance_penalty: float = 1.0  #: Karto's default (1: no distance penalty)
    angle_variance_penalty: float = 0.349  #: Karto's default
    minimum_angle_penalty: float = 0.9  #: Karto's default
    range_threshold: float | None = None  #: Karto's range threshold (metres; None: the laser's range)
    lattice_spacing: float = 1.0  #: base scans' positions this far apart (metres)
    lattice_clearance: float = 0.2  #: ... and at least this far from obstacles (metres)
    virtual_beam_deg: float = 0.25  #: beam spacing of the 360° base scans (degrees)
    base_surface: str = "run-centre"  #: on a grid: run-centre (mid-run) or near-face (ray cast)
    base_radius: float = 4.0  #: base scans within this of the guess (metres; 3.5 m + margin)
    min_response: float = 0.45  #: converged: final response ≥ this (slam_toolbox's loop match)
    score_window: float = 0.04  #: score's correlation window width (metres: ±2 cm)


@dataclass(frozen=True)
class _Stage:
    """One Karto matcher: its grid (created once) and how it is called."""

    search_size: float
    resolution: float
    smear: float
    penalize: bool
    refine: bool
    angle_offset_deg: float
    expand: bool


def _check_window(size_name: str, res_name: str, c: Config) -> None:
    """Karto asserts ``size / resolution`` is a whole number; an odd one gives an even-sized grid."""
    size, resolution = getattr(c, size_name), getattr(c, res_name)
    cells = size / resolution if resolution > 0 else float("nan")
    if not (size > 0 and resolution > 0 and abs(cells - round(cells)) < 1e-6 and round(cells) % 2 == 0):
        raise ParameterError(f"{size_name} / {res_name} must be an even whole number of cells (both > 0), got "
                             f"{size} / {resolution}", (size_name, res_name))


class KartoMatcher:
    """OpenKarto's correlative matcher, coarse then fine, against virtual scans of the map (see the module docstring)."""

    name = "karto"
    CONFIDENCE = Confidence("response", True, "Karto's correlation response")

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        self.config = resolve_params(Config, config, overrides)
        for size, res in (("coarse_search_size", "coarse_resolution"), ("fine_search_size", "fine_resolution"),
                          ("score_window", "fine_resolution")):
            _check_window(size, res, self.config)
        for smear, res in (("coarse_smear_deviation", "coarse_resolution"), ("fine_smear_deviation", "fine_resolution")):
            v, r = getattr(self.config, smear), getattr(self.config, res)
            if not 0.5 * r <= v <= 10.0 * r:  # Karto's own bounds, which it raises on at the first scan
                raise ParameterError(f"{smear} must be within 0.5 and 10 × {res} ({0.5 * r:g}…{10 * r:g}), got {v}",
                                     (smear,))
        self._wrappers: dict[tuple, object] = {}

    # -- Karto objects -------------------------------------------------------------------------------
    def _wrapper(self, stage: _Stage, threshold: float):  # noqa: ANN202 - a karto_scanmatcher.Wrapper
        key = (stage.search_size, stage.resolution, stage.smear, threshold)
        if key not in self._wrappers:
            cfg = ksm.ScanMatcherConfig()
            cfg.search_size, cfg.resolution = stage.search_size, stage.resolution
            cfg.smear_deviation, cfg.range_threshold = stage.smear, threshold
            self._wrappers[key] = ksm.Wrapper(cfg)
        wrapper = self._wrappers[key]
        c, k = self.config, wrapper.config
        k.coarse_search_angle_offset = math.radians(stage.angle_offset_deg)
        k.coarse_angle_resolution = math.radians(c.coarse_angle_resolution_deg)
        k.fine_search_angle_resolution = math.radians(c.fine_angle_resolution_deg)
        k.use_response_expansion = stage.expand
        k.distance_variance_penalty, k.minimum_distance_penalty = c.distance_variance_penalty, c.minimum_distance_penalty
        k.angle_variance_penalty, k.minimum_angle_penalty = c.angle_variance_penalty, c.minimum_angle_penalty
        return wrapper

    def _stages(self) -> tuple[_Stage, ...]:
        c = self.config
        coarse = _Stage(c.coarse_search_size, c.coarse_resolution, c.coarse_smear_deviation, False, True,
                        c.coarse_angle_offset_deg, c.use_response_expansion)
        fine = _Stage(c.fine_search_size, c.fine_resolution, c.fine_smear_deviation, True, True,
                      c.coarse_angle_offset_deg, c.use_response_expansion)
        return (coarse, fine) if c.coarse else (fine,)

    def _threshold(self, laser: LaserSpec) -> float:
        return float(self.config.range_threshold or laser.max_range)

    def _lattice(self, problem: Problem) -> ScanLattice:
        c = self.config
        return scan_lattice(problem.map, c.lattice_spacing, c.lattice_clearance, self._threshold(problem.laser),
                            c.virtual_beam_deg, c.base_surface)

    def _base_scans(self, problem: Problem) -> list:
        """Karto scans of the lattice positions within ``base_radius`` of the initial pose (cached per map)."""
        lattice = self._lattice(problem)
        return self._karto_scans(problem, lattice, lattice.near(problem.initial.xy, self.config.base_radius))

    def prepare(self, problem: Problem) -> None:
        """Ray-cast every lattice position's scan as a Karto scan (once per map; untimed by the harness)."""
        lattice = self._lattice(problem)
        self._karto_scans(problem, lattice, np.arange(len(lattice.positions)))

    def _karto_scans(self, problem: Problem, lattice: ScanLattice, idx: np.ndarray) -> list:
        """Karto scans of the lattice positions ``idx``, made once per map and position."""
        threshold = self._threshold(problem.laser)
        store = cached(problem.map, ("karto-scans", id(lattice), threshold), dict)
        missing = [int(i) for i in idx if int(i) not in store]
        if missing:
            for i, r in zip(missing, lattice.ranges(np.array(missing)), strict=True):
                p = lattice.positions[i]
                store[i] = _scan(lattice.laser, r, Pose(float(p[0]), float(p[1]), 0.0), threshold, i + 1)
        return [store[int(i)] for i in idx]

    # -- the matcher ---------------------------------------------------------------------------------
    def localize(self, problem: Problem) -> Estimate:
        """Coarse then fine Karto match of the real scan against the base scans near ``problem.initial``."""
        base = self._base_scans(problem)
        if not base:
            return Estimate(problem.initial, False, info={"status": "no-answer", "reason": "no free lattice position"})
        threshold = self._threshold(problem.laser)
        pose, responses, result = problem.initial, [], None
        for stage in self._stages():
            query = _scan(problem.laser, problem.ranges, pose, threshold, 0)
            result = self._wrapper(stage, threshold).match_scan(query, base, stage.penalize, stage.refine)
            best = result.best_pose
            pose = Pose(float(best.x), float(best.y), float(wrap_angle(best.yaw)))
            responses.append(float(result.response))
        cov = np.asarray(result.covariance, dtype=float)
        return Estimate(pose, responses[-1] >= self.config.min_response, iterations=len(responses),
                        info={"response": responses[-1], "coarse_response": responses[0] if len(responses) > 1 else None,
                              "base_scans": len(base), "var_x_m2": float(cov[0, 0]),
                              "var_y_m2": float(cov[1, 1]), "var_theta_rad2": float(cov[2, 2])})

    def score(self, problem: Problem, pose: Pose) -> float:
        """Minus Karto's response of the scan at ``pose`` (±2 cm, its heading); in [-1, 0], lower is better."""
        c = self.config
        base = self._base_scans(problem)
        if not base:
            return 0.0
        threshold = self._threshold(problem.laser)
        stage = _Stage(c.score_window, c.fine_resolution, c.fine_smear_deviation, False, False, 0.0, False)
        query = _scan(problem.laser, problem.ranges, pose, threshold, 0)
        return -float(self._wrapper(stage, threshold).match_scan(query, base, False, False).response)


def _scan(laser: LaserSpec, ranges: np.ndarray, pose: Pose, threshold: float, num: int):  # noqa: ANN202
    """A Karto ``LocalizedRangeScan`` of ``ranges`` at ``pose``; no-return beams lie beyond ``threshold``."""
    cfg = ksm.LaserScanConfig(laser.angle_min, laser.angle_min + laser.fov, laser.resolution, 0.0,
                              laser.max_range, threshold, "laser")
    beyond = max(threshold, laser.max_range) + 1.0
    r = np.where(laser.valid(ranges), ranges, beyond)
    p = ksm.Pose2(pose.x, pose.y, pose.theta)
    return ksm.LocalizedRangeScan(cfg, r.tolist(), p, p, num, 0.0)


REGISTRY = {"karto": {"class": "KartoMatcher", "docs": "baselines/karto.md", "summary": (
    "OpenKarto's correlative scan matcher (`karto-scanmatcher`, as in slam_toolbox) against "
    "virtual scans of the map, ±3.5 m / ±20° coarse then fine; licence LGPL-3.0 (OpenKarto; "
    "the wheel ships the GPL-3.0 text); optional: `pip install 'tfloc[karto]'`, Python ≤ 3.11"
    " only")}}
