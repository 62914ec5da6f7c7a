"""``mrpt-pf``: MRPT's particle-filter localization as it ships, the program ``pf-localization``
(Debian ``mrpt-apps``, MRPT 2.5.8) run as an external program.

For each sequence it writes, in a temporary directory: the map as a ROS map (``.yaml`` +
``.pgm``; a vector map rasterised at 5 cm, as for AMCL) turned into MRPT's ``.gridmap.gz`` by
MRPT's ``ros-map-yaml2mrpt``; the scans and wheel odometry as a CARMEN log turned into a rawlog
by MRPT's ``carmen2rawlog`` (:mod:`tfloc.baselines._mrpt_files`); and ``localization_demo.ini``
(``/usr/share/mrpt/config_files/pf-localization/``) with its filter options as shipped, only the
paths, the start pose and the headless switches changed (``SHOW_PROGRESS_3D_REAL_TIME=false``,
``3DSceneFrequency=-1``, one repetition). The start pose is given as every tracker gets it:
MRPT's initial distribution is a uniform box (``init_PDF_mode=1``, ``init_PDF_min/max_x/y/
yaw_deg``), here ±``init_half_xy_m`` and ±``init_half_theta_deg`` around it. The answer of each
scan is the particle set's mean MRPT logs after the filter step (``PDF estimation``); its own
confidence, ``info["sqrt_tr_cov"]``, the square root of the particle covariance's trace MRPT
logs beside it. CPU time: the child's, split over the scans in proportion to MRPT's own per-step
times (``exec_times.txt``). MRPT seeds its random generator from the clock
(``getRandomGenerator().randomize()``): runs do not repeat exactly. Values cited in
``docs/baselines/mrpt-pf.md``.
"""

from __future__ import annotations

import math
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
from tfloc.baselines._external import (
    ExternalProgramError,
    ProgramMissingError,
    find_program,
    read_table,
    run_program,
)

from tfloc.core.external import BatchAnswer, ExternalProgram, split_cpu
from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose
from tfloc.core.traits import Confidence
from tfloc.maps.ros_export import write_ros_map

from ._amcl_common import amcl_grid
from ._mrpt_files import carmen_lines, parse_estimates, render_ini

PACKAGE = "mrpt-apps"
CONFIG_DIR = Path("/usr/share/mrpt/config_files/pf-localization")
INI = "localization_demo.ini"


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`MrptPfTracker`: MRPT's ``.ini`` keys (section in the comment) with
    ``localization_demo.ini``'s values; metres, degrees where MRPT's keys say ``_deg``."""

    RULES: ClassVar[dict] = {
        ">= 1": ("aux_max_search_samples", "particles_count", "kld_max_samples", "kld_min_samples", "lf_decimation"),
        ">= 0": ("kld_min_samples_per_bin", "init_half_xy_m", "init_half_theta_deg", "lf_z_random"),
        "> 0": ("kld_bin_xy_m", "kld_bin_phi_deg", "kld_delta", "kld_epsilon", "lf_std_hit_m",
                "lf_max_corrs_distance_m", "lf_max_range_m", "dummy_min_std_xy_m", "dummy_min_std_phi_deg"),
        "[0, 1]": ("beta", "lf_z_hit"),
        (0, 1, 2, 3): ("pf_algorithm", "resampling_method"),
        (0, 1, 2, 3, 4, 5): ("likelihood_method",),
        (0, 1): ("adaptive_sample_size",),
    }

    pf_algorithm: int = 0  #: [PF_options] PF_algorithm: 0 standard proposal, 3 auxiliary PF with the optimal proposal
    resampling_method: int = 0  #: [PF_options] resamplingMethod: 0 multinomial
    adaptive_sample_size: int = 1  #: [PF_options] adaptiveSampleSize: KLD sampling on
    aux_max_search_samples: int = 10  #: [PF_options] pfAuxFilterOptimal_MaximumSearchSamples (PF_algorithm 3 only)
    beta: float = 0.5  #: [PF_options] BETA: resample when the effective sample size falls below it
    kld_bin_xy_m: float = 0.10  #: [KLD_options] KLD_binSize_XY (metres)
    kld_bin_phi_deg: float = 10.0  #: [KLD_options] KLD_binSize_PHI_deg (degrees)
    kld_delta: float = 0.01  #: [KLD_options] KLD_delta
    kld_epsilon: float = 0.01  #: [KLD_options] KLD_epsilon
    kld_max_samples: int = 40000  #: [KLD_options] KLD_maxSampleSize
    kld_min_samples: int = 150  #: [KLD_options] KLD_minSampleSize
    kld_min_samples_per_bin: int = 0  #: [KLD_options] KLD_minSamplesPerBin
    particles_count: int = 40000  #: [LocalizationExperiment] particles_count: the initial particles
    likelihood_method: int = 4  #: [..._likelihoodOpts] likelihoodMethod: 4 likelihood field (truncated), 1 beam model
    lf_decimation: int = 20  #: [..._likelihoodOpts] LF_decimation: every n-th beam
    lf_std_hit_m: float = 0.20  #: [..._likelihoodOpts] LF_stdHit (metres)
    lf_max_corrs_distance_m: float = 0.30  #: [..._likelihoodOpts] LF_maxCorrsDistance (metres)
    lf_z_hit: float = 0.95  #: [..._likelihoodOpts] LF_zHit
    lf_z_random: float = 0.05  #: [..._likelihoodOpts] LF_zRandom
    lf_max_range_m: float = 80.0  #: [..._likelihoodOpts] LF_maxRange (metres)
    dummy_min_std_xy_m: float = 0.10  #: [DummyOdometryParams] minStdXY: the odometry's Gaussian motion model (metres)
    dummy_min_std_phi_deg: float = 2.0  #: [DummyOdometryParams] minStdPHI (degrees)
    init_half_xy_m: float = 0.02  #: half-width of the initial uniform box in x and y around the start (metres; tfloc's)
    init_half_theta_deg: float = 1.0  #: half-width of its heading range (degrees; tfloc's)
    timeout_s: float = 14400.0  #: the longest one run of pf-localization may take (seconds)

    def ini_values(self) -> dict[tuple[str, str], object]:
        """The ``.ini`` lines these values set, ``(section, key) → value``."""
        lik = "MetricMap_occupancyGrid_00_likelihoodOpts"
        return {("PF_options", "PF_algorithm"): self.pf_algorithm,
                ("PF_options", "resamplingMethod"): self.resampling_method,
                ("PF_options", "adaptiveSampleSize"): self.adaptive_sample_size,
                ("PF_options", "pfAuxFilterOptimal_MaximumSearchSamples"): self.aux_max_search_samples,
                ("PF_options", "BETA"): self.beta,
                ("KLD_options", "KLD_binSize_XY"): self.kld_bin_xy_m,
                ("KLD_options", "KLD_binSize_PHI_deg"): self.kld_bin_phi_deg,
                ("KLD_options", "KLD_delta"): self.kld_delta, ("KLD_options", "KLD_epsilon"): self.kld_epsilon,
                ("KLD_options", "KLD_maxSampleSize"): self.kld_max_samples,
                ("KLD_options", "KLD_minSampleSize"): self.kld_min_samples,
                ("KLD_options", "KLD_minSamplesPerBin"): self.kld_min_samples_per_bin,
                ("LocalizationExperiment", "particles_count"): self.particles_count,
                (lik, "likelihoodMethod"): self.likelihood_method, (lik, "LF_decimation"): self.lf_decimation,
                (lik, "LF_stdHit"): self.lf_std_hit_m, (lik, "LF_maxCorrsDistance"): self.lf_max_corrs_distance_m,
                (lik, "LF_zHit"): self.lf_z_hit, (lik, "LF_zRandom"): self.lf_z_random,
                (lik, "LF_maxRange"): self.lf_max_range_m,
                ("DummyOdometryParams", "minStdXY"): self.dummy_min_std_xy_m,
                ("DummyOdometryParams", "minStdPHI"): self.dummy_min_std_phi_deg,
                # headless, one repetition, the start box as uniform over the box (not free cells)
                ("LocalizationExperiment", "SHOW_PROGRESS_3D_REAL_TIME"): False,
                ("LocalizationExperiment", "3DSceneFrequency"): -1,
                ("LocalizationExperiment", "experimentRepetitions"): 1,
                ("LocalizationExperiment", "init_PDF_mode"): 1}


def _version() -> str:
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", PACKAGE], capture_output=True,
                             text=True, timeout=10, check=False)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() or "unknown"


def _program(config: Config) -> ExternalProgram:
    find_program("pf-localization", PACKAGE)
    shipped = CONFIG_DIR / INI
    try:
        text = shipped.read_text()
    except OSError:
        raise ProgramMissingError(f"{shipped} not found (Debian: apt-get install {PACKAGE})") from None
    return ExternalProgram("pf-localization", PACKAGE, _version(), INI, render_ini(text, config.ini_values()))


class MrptPfTracker:
    """MRPT's ``pf-localization`` along a sequence (module notes); external program."""

    CONFIG = Config
    name = "mrpt-pf"
    kind = "tracker"  # (core.matcher.TRACKER)
    METHOD = "mrpt-pf"  # (tfloc.core.traits): MRPT's own particle filter, independent of AMCL's code
    CONFIDENCE = Confidence("sqrt_tr_cov", False, "sqrt of the trace of MRPT's particle covariance "
                            "(metres and radians mixed, as MRPT logs it)")
    EXTERNAL = True  # runs as its own program (tfloc matchers says so)

    def __init__(self, config: Config | None = None, **overrides: object) -> None:
        self.config = resolve_params(Config, config, overrides)
        self.program = _program(self.config)

    def run_batch(self, map: Map, laser: LaserSpec, ranges: list[np.ndarray], stamps: np.ndarray,
                  odometry: np.ndarray, start: Pose) -> BatchAnswer:
        n = len(ranges)
        with tempfile.TemporaryDirectory(prefix="tfloc-mrpt-") as tmp:
            d = Path(tmp)
            yaml_path = write_ros_map(amcl_grid(map), d / "map.yaml")
            run_program([find_program("ros-map-yaml2mrpt", PACKAGE), "-q", "-w", "-i", str(yaml_path)], d, tag="map")
            gridmap = d / "map.gridmap.gz"
            (d / "seq.log").write_text("\n".join(carmen_lines(laser, ranges, stamps, odometry)) + "\n")
            run_program([find_program("carmen2rawlog", PACKAGE), "-q", "-w", "-i", "seq.log", "-o", "seq.rawlog"],
                               d, tag="rawlog")
            c, h = self.config, math.degrees(start.theta)
            ini = render_ini(self.program.config_text, {
                ("LocalizationExperiment", "map_file"): gridmap, ("LocalizationExperiment", "rawlog_file"): d / "seq.rawlog",
                ("LocalizationExperiment", "logOutput_dir"): d / "out",
                ("LocalizationExperiment", "init_PDF_min_x"): start.x - c.init_half_xy_m,
                ("LocalizationExperiment", "init_PDF_max_x"): start.x + c.init_half_xy_m,
                ("LocalizationExperiment", "init_PDF_min_y"): start.y - c.init_half_xy_m,
                ("LocalizationExperiment", "init_PDF_max_y"): start.y + c.init_half_xy_m,
                ("LocalizationExperiment", "init_PDF_min_yaw_deg"): h - c.init_half_theta_deg,
                ("LocalizationExperiment", "init_PDF_max_yaw_deg"): h + c.init_half_theta_deg})
            (d / "run.ini").write_text(ini)
            run = run_program([find_program("pf-localization", PACKAGE), "run.ini"], d, timeout_s=c.timeout_s, tag="pf")
            poses, spread = parse_estimates(run.stdout.read_text(errors="replace") + run.stderr.read_text(errors="replace"))
            if len(poses) != n:
                raise ExternalProgramError(f"pf-localization logged {len(poses)} pose estimates for {n} scans "
                                           f"(carmen2rawlog or pf-localization dropped scans)")
            own = read_table(d / f"out_000_{c.particles_count:07d}" / "exec_times.txt", n, 1, "per-step times")[:, 0]
        cpu = run.cpu_s
        per_scan, how = split_cpu(cpu, n, own)
        info = tuple({"sqrt_tr_cov": float(s)} for s in spread)
        return BatchAnswer(poses, cpu, run.wall_s, per_scan, how, info)


REGISTRY = {"mrpt-pf": {"class": "MrptPfTracker", "docs": "baselines/mrpt-pf.md", "files": ["baselines/_mrpt_files.py"], "summary": (
    "a **tracker**, an **external program**: MRPT's own particle-filter localization, Debian "
    "`mrpt-apps`' `pf-localization` (MRPT 2.5.8: KLD sampling, likelihood field), run as it "
    "ships with `localization_demo.ini`'s filter options, headless; presets `mrpt-pf-optimal`"
    " (the auxiliary PF with the optimal proposal) and `mrpt-pf-lf-dense` (every 5th beam), "
    "each from MRPT's files ([docs/baselines/mrpt-pf.md](baselines/mrpt-pf.md)); missing "
    "program: one line, `apt-get install mrpt-apps` (`make browser` installs it)")}}
