"""The paper's perturbation protocol: its 3 × 3 offset bins and the one initial-pose sampler.

Every scan belongs to a stratum (cell): the initial distance offset ‖VP − true‖ in 0–1, 1–2 or
2–3 m, crossed with the initial angle offset |θ_VP − θ_true| in 0–5°, 5–10° or 10–15°; cell labels
are ``d{i}-a{j}``. Within a cell the distance offset is uniform, its direction uniform, and the
angle offset uniform with a random sign, each kept :data:`EDGE` inside its bin so that rounding
in a CSV file cannot move a scan into the next bin. The same sampler serves the simulated
datasets (:mod:`tfloc.datasets.synthetic`), the real logs (:mod:`tfloc.datasets.real`) and ROS
bags (:mod:`tfloc.datasets.from_bag`); the reports bin by the same edges
(:mod:`tfloc.evaluation.metrics`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from tfloc.core.map import Map
from tfloc.core.pose import Pose, wrap_angle
from tfloc.errors import DatasetError

DIST_BINS_M = ((0.0, 1.0), (1.0, 2.0), (2.0, 3.0))
ANGLE_BINS_DEG = ((0.0, 5.0), (5.0, 10.0), (10.0, 15.0))
EDGE = 1e-4  # offsets stay this far inside their bin (m / deg)
DEFAULT_SEED = 20091122  # of the real logs' and bags' perturbations

#: Which positions an initial pose may take: ``(N, 2)`` metres → ``(N,)`` bool.
Accept = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Stratum:
    """One cell of the grid: initial distance offset range (m) × angle offset range (degrees)."""

    label: str
    dist_m: tuple[float, float]
    angle_deg: tuple[float, float]


def strata() -> list[Stratum]:
    """The 3 × 3 grid ``d1-a1 … d3-a3`` of the paper's protocol, distance-major."""
    return [Stratum(f"d{i + 1}-a{j + 1}", d, a)
            for i, d in enumerate(DIST_BINS_M) for j, a in enumerate(ANGLE_BINS_DEG)]


def initial_pose(truth: Pose, cell: Stratum, rng: np.random.Generator, accept: Accept,
                 tries: int = 64) -> Pose | None:
    """An initial pose (VP) offset from ``truth`` as ``cell`` prescribes, at an accepted position.

    Draws ``tries`` candidates at once (distances, directions, angle magnitudes, signs, in that
    order) and returns the first one ``accept`` takes, or ``None`` if it takes none."""
    (dlo, dhi), (alo, ahi) = cell.dist_m, cell.angle_deg
    d = rng.uniform(dlo + EDGE, dhi - EDGE, size=tries)
    phi = rng.uniform(-math.pi, math.pi, size=tries)
    da = np.radians(rng.uniform(alo + EDGE, ahi - EDGE, size=tries))
    sign = np.where(rng.random(tries) < 0.5, -1.0, 1.0)
    xy = np.column_stack((truth.x + d * np.cos(phi), truth.y + d * np.sin(phi)))
    ok = np.flatnonzero(accept(xy))
    if not ok.size:
        return None
    k = ok[0]
    return Pose(float(xy[k, 0]), float(xy[k, 1]), float(wrap_angle(truth.theta + sign[k] * da[k])))


@dataclass(frozen=True)
class Perturbation:
    """How initial poses are drawn for given true poses: the seed, the free-space clearance (m)
    and how many candidates to draw per scan before giving up."""

    seed: int = DEFAULT_SEED
    clearance_m: float = 0.2
    max_draws: int = 10_000


def perturb(truths: np.ndarray, map_: Map | Sequence[Map],
            cfg: Perturbation = Perturbation()) -> tuple[np.ndarray, list[str]]:
    """Initial poses ``(N, 3)`` and cell labels for given true poses ``(N, 3)`` (metres, radians).

    Scan k gets cell ``perm[k] mod 9`` (a seeded, balanced assignment) and an
    :func:`initial_pose` in it, inside the map's bounds and at least ``clearance_m`` from its
    geometry (``map_`` is one map for all, or one map per scan), drawn again until one is
    accepted (at most ``max_draws`` candidates, else a :class:`~tfloc.errors.DatasetError`)."""
    maps = [map_] * len(truths) if isinstance(map_, Map) else list(map_)

    def acceptor(m: Map) -> Accept:
        def accept(xy: np.ndarray) -> np.ndarray:
            ok = m.in_bounds(xy)
            ok[ok] = m.is_free(xy[ok], cfg.clearance_m)
            return ok
        return accept

    rng = np.random.default_rng(cfg.seed)
    cells = strata()
    assign = rng.permutation(len(truths)) % len(cells)
    init = np.empty((len(truths), 3))
    for k, c in enumerate(assign):
        cell, truth, accept = cells[int(c)], Pose.from_array(truths[k]), acceptor(maps[k])
        for _ in range(max(1, cfg.max_draws // 64)):
            pose = initial_pose(truth, cell, rng, accept)
            if pose is not None:
                break
        else:
            raise DatasetError(f"scan {k}: no free initial position in cell {cell.label} "
                               f"after {cfg.max_draws} draws")
        init[k] = pose.as_array()
    return init, [cells[int(c)].label for c in assign]
