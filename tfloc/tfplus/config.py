"""``tf-plus``'s configuration (:class:`TfPlusConfig`) and what follows from it alone: the map views
it asks for and its read-only heading offsets (shared by the staged matcher,
:mod:`tfloc.tfplus.matcher`, and the one-call pipeline, :mod:`tfloc.tfplus.pipeline`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import ClassVar

import numpy as np

from tfloc.core.map import Map
from tfloc.core.presets import preset_params
from tfloc.paper.shape import ShapeConfig

from .refine import RefineConfig
from .view import MapView, map_view


@dataclass(frozen=True)
class TfPlusConfig:
    """Parameters of ``tf-plus`` (metres, radians).

    Attributes:
        refine_to: what the refinement fits the scan to: ``"field"``, the map itself (each
            scan point's nearest map point; on a grid map also the walls' surfaces and the
            returns' depth behind them, :func:`tfloc.tfplus.refine.refine_to_field`); ``"virtual"``,
            ray-cast virtual scans (:func:`tfloc.tfplus.refine.refine`: exact on a vector map, whose
            walls have no thickness, and biased short on a grid whose walls are drawn several
            cells thick); ``"auto"``: ``"field"`` on a grid map, ``"virtual"`` on any other.
        select: how the final answer is picked among refined candidates: ``"residual"``
            (truncated point-to-line residual to the map's points), ``"virtual"`` (the same to
            the virtual scans) or ``"tf"`` (turning-function Err, Eq. 13).
        wall_thickness: on a grid map, walls are followed this far (metres) across to find their
            surfaces (:mod:`tfloc.maps.walls`).
        scan_stride: every ``scan_stride``-th real point is used by the first coarse level
            (if ``coarse_points`` is 0; else about ``coarse_points`` points, evenly spread,
            whatever the scanner's beam count).
        coarse_bound: score the coarse search on the distance field pooled over ± half a
            lattice step (a lower bound over each lattice cell), so that the cell holding the
            true pose is not outscored because its lattice point is a few cm off a wall.
        tie_tolerance: candidates whose cost is within this fraction of the best are a tie
            (the scan sees the same geometry from both, e.g. a bare corner), broken by
            distance to the VP (0: no tie-break).
        free_distance: coarse search: a scan point in the map's known free space counts at most
            this far from the map (metres; a return from an unmapped object in front of a wall
            looks like a wrong pose's point to a distance field,
            :func:`tfloc.tfplus.view.free_capped`); ``None``: every point up to
            ``field_truncation``.
        short_margin: a return that ends more than this short of the map's surface along its beam
            (metres; the map clear of walls that far beyond it) is **short**: an object the map
            lacks stopped it, not a pose error of a few cm (:func:`tfloc.tfplus.cost.short_beams`).
        short_residual: selection: a short return counts at most this residual (metres;
            :mod:`tfloc.tfplus.cost`); ``None``: like any other return.
        object_extent: with it, short returns count as an unmapped object (in the selection and
            the refinement) only as a whole group of consecutive returns of the scan at most this
            long from first to last point (metres; a person, a box, a cart): a wall's worth of
            short returns, or a part of a group, says the pose is wrong
            (:func:`tfloc.tfplus.cost.object_groups`); ``None``: each short return on its own.
        short_refine: refinement against the map itself (grid maps, ``refine_to="field"``):
            short returns at a candidate's coarse pose are left out of its refinement, each
            candidate refined on its own returns and none pruned (:mod:`tfloc.tfplus.unmapped`).
        see_through_share: selection: see-through beams count ``inlier_distance²`` each up to
            this share of the beams; beyond it their penalty is scaled down so that together
            they weigh that share (a map whose furniture is gone makes many beams pass where it
            has obstacles, at the true pose too). 1: every see-through beam in full.
        shape: the scan-shape parameters (ShortStraw, polygon closure) of the turning-function
            seed and of the ``select="tf"`` Err; the resampling distance is 5 cm (the paper's
            S = 1 m gives edges too coarse for their directions to be a heading estimate).
    """

    RULES: ClassVar[dict] = {  # rule → parameters it applies to (core.params)
        "> 0": ("grid_step", "heading_step", "field_resolution", "field_truncation",
                "short_margin"),
        ">= 0": ("search_radius", "clearance", "rotation_seeds", "max_rotation", "heading_span",
                 "separation", "tie_tolerance", "wall_thickness", "coarse_points",
                 "free_distance", "short_residual", "object_extent"),
        "[0, 1]": ("see_through_share",),
        ">= 1": ("scan_stride", "shortlist", "candidates", "min_returns"),
        "finite": ("heading_offsets",),
        ("residual", "virtual", "tf"): ("select",),
        ("auto", "field", "virtual"): ("refine_to",)}

    tf_seed: bool = True  #: add headings seeded by the turning-function rotation estimates
    heading_sweep: bool = True  #: sweep the headings θ_VP ± heading_span
    grid: bool = True  #: coarse grid search over positions (else only the VP's position)
    refine: bool = True  #: run the point-to-line refinement
    refine_to: str = "auto"
    select: str = "residual"
    search_radius: float = 3.3  #: radius of the coarse search around the VP (metres)
    grid_step: float = 0.2  #: lattice spacing of the coarse search (metres)
    clearance: float = 0.1  #: least distance of a lattice position from walls (metres)
    #: headings tried around each seed (radians)
    heading_offsets: tuple[float, ...] = tuple(math.radians(d) for d in (-1.0, 0.0, 1.0))
    rotation_seeds: int = 3  #: rotations from the edge-direction histograms (.headings) ...
    max_rotation: float = math.radians(20.0)  #: ... within ± this of θ_VP (radians)
    heading_span: float = math.radians(17.0)  #: the sweep covers θ_VP ± this (radians) ...
    heading_step: float = math.radians(3.0)  #: ... at this spacing (radians)
    field_resolution: float = 0.05  #: cell size of the distance field (metres)
    field_truncation: float = 0.3  #: truncation of the distance field (metres)
    wall_thickness: float = 0.3
    scan_stride: int = 9
    coarse_points: int = 20  #: about this many points on the first coarse level (see scan_stride)
    coarse_bound: bool = True
    shortlist: int = 64  #: the first level's best poses rescored on all points
    candidates: int = 4  #: candidates refined
    separation: float = 0.3  #: least distance between candidates (metres)
    min_returns: int = 10  #: fewer valid returns than this is a no-answer
    tie_tolerance: float = 0.1
    beam_check: bool = True  #: count see-through beams in the selection cost (.cost)
    free_distance: float | None = None
    short_margin: float = 0.3
    short_residual: float | None = None
    object_extent: float | None = None
    short_refine: bool = False
    see_through_share: float = 1.0
    refinement: RefineConfig = RefineConfig()  #: the point-to-line refinement's parameters
    shape: ShapeConfig = ShapeConfig(spacing=0.05)


#: ``tf-plus``'s changed-world configuration, the preset ``tf-plus-changed`` (``tfloc/presets.toml``,
#: ``docs/robustness.md``): overrides of :class:`TfPlusConfig` for a world that has changed since it
#: was mapped (people, carts, doors, furniture moved or gone). Not the default: on the paper
#: protocol it gives the same success, on the real recordings it can lose (ACES) and it costs more CPU.
CHANGED_WORLD = preset_params("tf-plus-changed")


def field_view(map_: Map, cfg: TfPlusConfig) -> MapView:
    """The map's view (:mod:`tfloc.tfplus.view`), built once per map and configuration."""
    return map_view(map_, cfg.field_resolution, cfg.field_truncation, cfg.wall_thickness)


def coarse_view(map_: Map, cfg: TfPlusConfig) -> MapView:
    """The view the coarse search scores on: pooled over ± half a lattice step
    (``coarse_bound``), else the view itself; capped in free space (``free_distance``)."""
    return map_view(map_, cfg.field_resolution, cfg.field_truncation, cfg.wall_thickness,
                    cfg.grid_step / 2.0 if cfg.coarse_bound else 0.0, cfg.free_distance)


@lru_cache(maxsize=16)
def sweep(span: float, step: float) -> np.ndarray:
    """The sweep's offsets ``k·step`` for ``|k| ≤ round(span / step)`` (radians; read-only)."""
    k = int(round(span / step))
    out = np.arange(-k, k + 1) * step
    out.setflags(write=False)
    return out


@lru_cache(maxsize=16)
def heading_offsets(offsets: tuple[float, ...]) -> np.ndarray:
    """``offsets`` as a read-only array (radians)."""
    out = np.asarray(offsets, dtype=float)
    out.setflags(write=False)
    return out


def coarse_search(map_: Map, cfg: TfPlusConfig) -> tuple:
    """What :func:`~tfloc.tfplus.coarse_kernel.coarse_kernel` takes of ``cfg`` and of the view it
    scores on (:func:`coarse_view`): the table, its corner and cell size, the points' count or
    stride, the shortlist, the candidates, their separation and the lattice step."""
    pooled = coarse_view(map_, cfg)
    return (pooled.table, float(pooled.origin[0]), float(pooled.origin[1]), pooled.resolution,
            int(cfg.coarse_points), int(cfg.scan_stride), int(cfg.shortlist), int(cfg.candidates),
            float(cfg.separation), float(cfg.grid_step))
