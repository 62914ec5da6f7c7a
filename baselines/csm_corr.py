"""``csm-corr``: real-time correlative scan matching (Olson, ICRA 2009) against a likelihood field.

Inputs are the map, the laser spec, the real scan and the initial pose (never the truth). Choices
and why (the detail: ``docs/baselines/csm-corr.md``):

* **Likelihood field of the map** (:mod:`tfloc.baselines.likelihood`): ``exp(-d² / 2σ²)`` of the
  distance ``d`` to the map, ``sigma`` wide enough that an endpoint 10 m out, off by half a
  rotation step, still scores, so the discrete search does not skip the right rotation.
* **Exhaustive search over the protocol's whole window** about the initial pose (``window_xy``,
  ``window_theta_deg``, steps ``rot_step_deg`` and ``xy_step_cells``); a pose scores the sum of its
  endpoints' likelihoods (Olson's rasterised lookup table, all beams weighted alike).
* **Olson's multi-resolution scheme**: the field max-pooled over blocks of ``block`` steps bounds
  every translation of a block; blocks are expanded best bound first until no bound beats the best
  score: exactly the full grid's best pose, without scoring most of it.
* **Fine refinement**: ``scipy.optimize.least_squares`` on the interpolated distance field with a
  Cauchy loss (the likelihood's robust shape) removes the grid's quantisation.
* ``converged`` = the refinement succeeded and the grid score is at least ``min_mean_likelihood``
  per beam: a self-check, not a claim of correctness.

**Amortised per map** (``prepare``): the distance and likelihood fields and the max-pooled table.
**Per scan**: the search's look-ups, the block expansion and the refinement.

``score(problem, pose)``: the negative mean likelihood ``-mean exp(-d² / 2σ²)`` of the scan
endpoints at ``pose`` (interpolated distance ``d``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.optimize import least_squares

from tfloc.core.params import Configured
from tfloc.core.pose import Pose, wrap_angle
from tfloc.core.problem import Estimate, Problem
from tfloc.core.traits import Confidence

from .likelihood import LikelihoodField, likelihood_field


@dataclass(frozen=True)
class Config:
    """Parameters of :class:`CorrelativeMatcher` (metres, degrees where named)."""

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("resolution", "sigma", "rot_step_deg", "refine_scale"),
        ">= 0": ("window_xy", "window_theta_deg", "min_mean_likelihood"),
        ">= 1": ("xy_step_cells", "block", "expand_batch", "refine_max_evals")}

    resolution: float = 0.02  #: cell size of the likelihood field (metres)
    sigma: float = 0.10  #: σ of the likelihood exp(−d²/2σ²) (metres)
    window_xy: float = 3.5  #: search ± this in x and in y about the guess (metres)
    window_theta_deg: float = 20.0  #: search ± this in heading (degrees)
    rot_step_deg: float = 1.0  #: heading step of the search (degrees)
    xy_step_cells: int = 2  #: translation step of the search (cells)
    block: int = 8  #: translation steps per side of a low-resolution block
    expand_batch: int = 8  #: blocks expanded per vectorised round
    refine_scale: float = 0.05  #: Cauchy loss scale of the refinement (metres)
    refine_max_evals: int = 200  #: refinement: least_squares' max_nfev
    min_mean_likelihood: float = 0.3  #: converged needs this mean likelihood per beam (0–1)


@dataclass(frozen=True)
class _Grid:
    """The discrete search: rotations, translation steps (cells) and block origins."""

    thetas: np.ndarray  # (R,) absolute headings, radians
    steps: np.ndarray  # (T,) translation offsets along one axis, in cells
    block_starts: np.ndarray  # (B,) offsets of each block's first translation, in cells


class CorrelativeMatcher(Configured):
    """Olson's real-time correlative scan matcher over the protocol's window (see the module docstring)."""

    name = "csm-corr"
    CONFIDENCE = Confidence("grid_mean_likelihood", True, "the best pose's mean likelihood per point")
    CONFIG = Config

    def _field(self, problem: Problem) -> LikelihoodField:
        c = self.config
        # A zero band twice the translation reach wide: endpoints beyond it are clamped onto it (see
        # ``localize``), so the field's size does not grow with the laser's range.
        reach = c.window_xy + (c.block + 1) * c.xy_step_cells * c.resolution
        return likelihood_field(problem.map, c.resolution, c.sigma, 2.0 * reach + 0.5)

    def _grid(self, initial: Pose) -> _Grid:
        c = self.config
        n_rot = int(math.floor(c.window_theta_deg / c.rot_step_deg + 1e-9))
        thetas = initial.theta + np.radians(c.rot_step_deg) * np.arange(-n_rot, n_rot + 1)
        n_xy = int(math.ceil(c.window_xy / (c.xy_step_cells * c.resolution) - 1e-9))
        steps = c.xy_step_cells * np.arange(-n_xy, n_xy + 1)
        block_starts = steps[:: c.block]
        return _Grid(thetas, steps, block_starts)

    def _span(self) -> int:
        """The side, in cells, of the max-pooling window of one block of translations (odd)."""
        return (self.config.block - 1) * self.config.xy_step_cells + 1

    def prepare(self, problem: Problem) -> None:
        """Build the likelihood field and its pooled table (once per map; untimed by the harness)."""
        self._field(problem).max_pooled(self._span())

    def localize(self, problem: Problem) -> Estimate:
        """Search the window about ``problem.initial`` exhaustively (multi-resolution), then refine."""
        c = self.config
        field = self._field(problem)
        pts = problem.points
        grid = self._grid(problem.initial)
        h, w = field.shape
        # Endpoint cells for every rotation, translation zero: (R, N) flat indices.
        cos, sin = np.cos(grid.thetas)[:, None], np.sin(grid.thetas)[:, None]
        wx = problem.initial.x + cos * pts[:, 0] - sin * pts[:, 1]
        wy = problem.initial.y + sin * pts[:, 0] + cos * pts[:, 1]
        cells = field.cells(np.stack((wx, wy), axis=-1))
        # Translations move a cell by -lo … +hi cells. An endpoint that far beyond the map scores 0 at
        # every translation; clamping it keeps all its lookups inside the field's zero band.
        lo = -int(grid.steps[0])
        hi = int(grid.steps[-1]) + c.block * c.xy_step_cells
        cx = np.clip(cells[..., 0], lo, w - 1 - hi)
        cy = np.clip(cells[..., 1], lo, h - 1 - hi)
        base = cy * w + cx

        # Low resolution: upper bounds for every (rotation, block_y, block_x).
        pooled = field.max_pooled(self._span()).ravel()
        bs = grid.block_starts
        block_off = (bs[:, None] * w + bs[None, :]).ravel()  # (B²,), y-major
        bounds = np.take(pooled, base[:, :, None] + block_off[None, None, :]).sum(axis=1)  # (R, B²)
        order = np.argsort(-bounds, axis=None, kind="stable")  # ties: the first block (any CPU)
        flat_bounds = bounds.ravel()[order]

        # Full resolution inside blocks, best bound first, until no bound can beat the best score.
        within = c.xy_step_cells * np.arange(c.block)
        in_block = (within[:, None] * w + within[None, :]).ravel()  # (block²,)
        lik = field.likelihood.ravel()
        best, best_pose_idx, expanded = -np.inf, None, 0
        nb = len(block_off)
        while expanded < len(order) and flat_bounds[expanded] > best:
            sel = order[expanded: expanded + c.expand_batch]
            r_idx, b_idx = np.divmod(sel, nb)
            offs = block_off[b_idx][:, None] + in_block[None, :]  # (k, block²)
            scores = np.take(lik, base[r_idx][:, :, None] + offs[:, None, :]).sum(axis=1)  # (k, block²)
            k, j = np.unravel_index(np.argmax(scores), scores.shape)
            if scores[k, j] > best:
                best = float(scores[k, j])
                by, bx = divmod(int(b_idx[k]), len(bs))
                jy, jx = divmod(int(j), c.block)
                best_pose_idx = (int(r_idx[k]), int(bs[by] + within[jy]), int(bs[bx] + within[jx]))
            expanded += len(sel)
        r_i, dy, dx = best_pose_idx
        grid_pose = Pose(problem.initial.x + dx * c.resolution, problem.initial.y + dy * c.resolution,
                         float(wrap_angle(grid.thetas[r_i])))

        pose, ok, nfev = self._refine(field, pts, grid_pose)
        mean_lik = best / max(len(pts), 1)
        return Estimate(pose, bool(ok and mean_lik >= c.min_mean_likelihood), iterations=expanded,
                        evaluations=int(expanded * c.block**2 + nfev),
                        info={"grid_mean_likelihood": mean_lik, "blocks_expanded": int(expanded),
                              "blocks_total": int(len(order)), "refine_evals": int(nfev)})

    def _refine(self, field: LikelihoodField, pts: np.ndarray, start: Pose) -> tuple[Pose, bool, int]:
        """Fine local refinement: robust least squares on the interpolated distance field."""

        def residuals(v: np.ndarray) -> np.ndarray:
            return field.distance_at(Pose(v[0], v[1], v[2]).transform(pts))

        sol = least_squares(residuals, start.as_array(), loss="cauchy", f_scale=self.config.refine_scale,
                            x_scale=np.array([0.01, 0.01, 0.002]), diff_step=np.array([1e-4, 1e-4, 1e-4]),
                            max_nfev=self.config.refine_max_evals, method="trf")
        v = sol.x
        return Pose(float(v[0]), float(v[1]), float(wrap_angle(v[2]))), bool(sol.success), int(sol.nfev)

    def score(self, problem: Problem, pose: Pose) -> float:
        """Negative mean likelihood of the scan endpoints at ``pose`` (in [-1, 0]; lower is better)."""
        field = self._field(problem)
        return -float(np.mean(field.likelihood_at(pose.transform(problem.points))))


REGISTRY = {"csm-corr": {"class": "CorrelativeMatcher", "docs": "baselines/csm-corr.md", "summary": (
    "Olson's real-time correlative scan matching (±3.5 m, ±20°, multi-resolution)")}}
