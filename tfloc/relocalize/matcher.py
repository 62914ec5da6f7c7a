"""``tf-global``: the project's own global localizer (no initial guess), a turning-function place
index resolved by ``tf-plus``.

1. **Index** (map-only work, :mod:`tfloc.relocalize.index`, built in ``prepare``): signatures of
   virtual scans from a lattice of free positions × a few headings, cached on disk under the
   map's content hash.
2. **Query**: the real scan's signature (:mod:`tfloc.relocalize.signature`: heading-invariant,
   from the turning function's turning angles, the wall lengths and the ranges) and its range
   profile (:mod:`tfloc.relocalize.profile`: sector medians, a real scan's no-returns unknown,
   compared with a truncated distance over shifts that cover the gap between two index headings)
   → the ``places`` nearest distinct index entries.
3. **Resolve** the places with ``tf-plus``'s stages, configured by ``resolver``: each place's
   pose is the guess of its turning-function heading seeds, heading sweep and coarse grid (over
   ``resolver.search_radius`` around the place); the coarse candidates of all places compete
   and the best ``refined`` go through one point-to-line refinement
   (:mod:`tfloc.relocalize.resolve`, ``resolve="batched"``), or ``tf-plus``'s whole
   ``localize`` runs from each place (``resolve="per-place"``: twice the CPU, measured).
4. **Rank** the resolved poses by ``tf-plus``'s selection cost (:mod:`tfloc.tfplus.cost`); the
   answer is the lowest, ``hypotheses`` the best distinct ones (best first).

A local problem (an initial guess given) is answered by ``tf-plus`` from that guess
(``local="tf-plus"``) or searched globally, ignoring the guess (``local="global"``). The true
pose is never read. ``docs/tf-global.md`` has the measurements behind the defaults.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tfloc.core.params import resolve_params
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem
from tfloc.tfplus.matcher import TfPlusConfig, TurningFunctionPlusMatcher

from .index import IndexConfig, PlaceIndex, place_index
from .profile import FAR, UNKNOWN, query_profiles, query_shifts
from .resolve import resolve_places
from .signature import scan_signature

#: tf-plus as a resolver of one place: its search covers the place's lattice cell and more (0.35 m
#: lattice), its heading sweep (± 17°) the gap between two of the index's headings (22.5°).
RESOLVER = TfPlusConfig(search_radius=0.5, tie_tolerance=0.0)


@dataclass(frozen=True)
class TfGlobalConfig:
    """Parameters of ``tf-global`` (metres, radians).

    Attributes:
        place_density: places resolved per scan: also at least this many per m² of the map's
            free area (a map twice the size holds about twice the places that look alike;
            0.08/m² gives the 24 places chosen on the development offices, 270–300 m²).
        resolve: ``"per-place"`` (tf-plus's ``localize`` from each place) or ``"batched"`` (its
            stages, the coarse candidates of all places competing for one refinement of the
            best ``refined``: :mod:`tfloc.relocalize.resolve`).
        profile_weight: weight of the robust range-profile distance (a mean of per-sector
            differences in fractions of the profile's cap) beside the signature's Euclidean
            distance; 0 ranks by the signature alone.
        profile_truncation: a sector's difference counts at most this (fraction of the cap):
            a few sectors that see through glass or a door the map drew closed cost a bounded
            amount.
        profile_shifts: the query's profile at this many shifts over ± half the gap between two
            index headings (the best shift counts).
        no_return: a real scan's no-return beam is ``"unknown"`` (left out of the profile) or
            ``"far"`` (the cap, as open space in the map).
        local: a problem with an initial guess: ``"tf-plus"`` (``tf-plus`` with its own defaults
            from the guess: the local matcher) or ``"global"`` (the guess ignored).
        cache_dir: where the index is stored on disk ("" = ``$TFLOC_INDEX_CACHE`` or
            ``~/.cache/tfloc/index``).
    """

    RULES: ClassVar[dict] = {
        ">= 1": ("places", "hypotheses", "refined", "profile_shifts"),
        ("per-place", "batched"): ("resolve",),
        ">= 0": ("place_density", "place_separation", "place_heading_separation", "hypothesis_separation",
                 "hypothesis_heading_separation", "profile_weight"),
        ("tf-plus", "global"): ("local",),
        "> 0": ("profile_truncation",),
        (UNKNOWN, FAR): ("no_return",)}

    places: int = 24  #: index places resolved per scan, at least (see place_density)
    place_density: float = 0.08
    place_separation: float = 0.5  #: index entries within this distance (metres; the resolver reaches 0.5 m) ...
    place_heading_separation: float = math.radians(30.0)  #: ... and heading (rad): one place
    hypotheses: int = 5  #: ranked answers returned (Estimate.hypotheses; scored: 5)
    hypothesis_separation: float = 0.3  #: hypotheses are at least this far apart (metres) ...
    hypothesis_heading_separation: float = math.radians(10.0)  #: ... or this in heading (rad)
    resolve: str = "batched"
    refined: int = 16  #: batched: candidates refined (see resolve)
    profile_weight: float = 10.0
    profile_truncation: float = 0.1
    profile_shifts: int = 9
    no_return: str = UNKNOWN
    local: str = "tf-plus"
    cache_dir: str = ""
    disk_cache: bool = True  #: store and read the index on disk (else once per process)
    index: IndexConfig = IndexConfig()  #: the place index
    resolver: TfPlusConfig = RESOLVER  #: tf-plus's parameters when it resolves a place


def distinct(poses: np.ndarray, count: int, separation: float, heading_separation: float) -> list[int]:
    """Indices of up to ``count`` of ``(K, 3)`` poses (given best first), skipping any within
    ``separation`` metres and ``heading_separation`` radians of one already kept."""
    keep: list[int] = []
    for i, p in enumerate(poses):
        near = [np.hypot(*(p[:2] - poses[j, :2])) <= separation
                and abs(math.remainder(p[2] - poses[j, 2], 2 * math.pi)) <= heading_separation
                for j in keep]
        if not any(near):
            keep.append(i)
            if len(keep) == count:
                break
    return keep


class TurningFunctionGlobalMatcher:
    """``tf-global``: turning-function place index → ``tf-plus``'s stages per place → its
    selection cost."""

    name = "tf-global"
    CONFIG = TfGlobalConfig
    solves_global = True

    def __init__(self, config: TfGlobalConfig | None = None, **overrides) -> None:
        self.config = resolve_params(TfGlobalConfig, config, overrides)
        self.resolver = TurningFunctionPlusMatcher(self.config.resolver)
        self.local = TurningFunctionPlusMatcher()

    def index(self, problem: Problem) -> PlaceIndex:
        """The map's place index for the problem's laser (built or loaded once per map)."""
        cfg = self.config
        return place_index(problem.map, problem.laser, cfg.index, cfg.cache_dir, cfg.disk_cache)

    def prepare(self, problem: Problem) -> None:
        """Build or load the place index and tf-plus's map view (map-only work, untimed by the
        harness)."""
        idx = self.index(problem)
        if len(idx.poses):
            at = dataclasses.replace(problem, initial=Pose.from_array(idx.poses[0]))
            self.resolver.prepare(at)
            self.resolver.score(at, at.initial)     # the cost's kernels compiled or loaded
        if problem.initial is not None and self.config.local == "tf-plus":
            self.local.prepare(problem)

    def localize(self, problem: Problem) -> Estimate:
        cfg = self.config
        if problem.initial is not None and cfg.local == "tf-plus":
            est = self.local.localize(problem)
            return dataclasses.replace(est, hypotheses=(est.pose,), info={**est.info, "mode": "local"})
        points = problem.points
        if len(points) < cfg.resolver.min_returns:
            return Estimate(Pose(math.nan, math.nan, math.nan), False, 0, 0, {
                "status": "no-answer", "reason": f"{len(points)} returns (< {cfg.resolver.min_returns})"})
        idx = self.index(problem)
        if len(idx.poses) == 0:
            return Estimate(Pose(math.nan, math.nan, math.nan), False, 0, 0, {
                "status": "no-answer", "reason": "the map has no free lattice position to index"})
        sig = scan_signature(problem.ranges, problem.laser, cfg.index.signature)
        prof = (query_profiles(problem.ranges, problem.laser, cfg.index.profile,
                               query_shifts(cfg.index.headings, cfg.profile_shifts), cfg.no_return)
                if cfg.profile_weight > 0 else None)
        count = max(cfg.places, int(round(cfg.place_density * idx.free_area_m2)))
        entries, sig_dist = idx.query(sig, count, cfg.place_separation, cfg.place_heading_separation,
                                      profiles=prof, profile_weight=cfg.profile_weight,
                                      truncation=cfg.profile_truncation)
        if cfg.resolve == "batched":
            ranked, cost, evaluations = resolve_places(problem, idx.poses[entries], cfg.resolver,
                                                       cfg.refined)
            return self._answer(ranked, cost, idx.poses[entries], evaluations, sig_dist)
        poses, costs, evaluations = [], [], 0
        for e in entries:
            guess = dataclasses.replace(problem, initial=Pose.from_array(idx.poses[e]))
            est = self.resolver.localize(guess)
            evaluations += est.evaluations
            if est.info.get("status") != "ok" or not est.pose.is_finite():
                continue
            poses.append(est.pose.as_array())
            costs.append(float(est.info["cost"]))
        if not poses:
            return Estimate(Pose(math.nan, math.nan, math.nan), False, 1, evaluations,
                            {"status": "no-answer", "reason": "no place resolved"})
        return self._answer(np.asarray(poses), np.asarray(costs), idx.poses[entries], evaluations, sig_dist)

    def _answer(self, poses: np.ndarray, costs: np.ndarray, places: np.ndarray, evaluations: int,
                sig_dist: np.ndarray) -> Estimate:
        """The estimate: resolved ``poses`` ranked by their selection ``costs``, the best
        distinct ones as hypotheses; ``info["proposed"]`` keeps the index's ``places`` ``(P, 3)``
        in signature order (millimetres, milliradians), so a report can tell a place the index
        never proposed from one the resolution missed."""
        cfg = self.config
        order = np.argsort(costs, kind="stable")
        ranked = poses[order]
        keep = distinct(ranked, cfg.hypotheses, cfg.hypothesis_separation,
                        cfg.hypothesis_heading_separation)
        hyps = tuple(Pose.from_array(ranked[k]) for k in keep)
        info = {"status": "ok", "mode": "global", "places": len(places),
                "proposed": np.round(np.asarray(places, dtype=float), 3).tolist(),
                "cost": float(costs[order[0]]), "costs": [float(costs[order[k]]) for k in keep],
                "signature_distance": float(sig_dist[0]) if len(sig_dist) else math.nan}
        return Estimate(hyps[0], True, len(places), evaluations, info, hyps)

    def score(self, problem: Problem, pose: Pose | None) -> float:
        """``tf-plus``'s selection objective at ``pose`` (the root mean square of the truncated
        per-beam residuals, metres; :meth:`TurningFunctionPlusMatcher.score`); NaN for no pose
        (a warm-up that scores a global problem's missing guess)."""
        if pose is None:
            return math.nan
        return self.resolver.score(problem, pose)


REGISTRY = {"tf-global": {"class": "TurningFunctionGlobalMatcher", "docs": "tf-global.md", "files": ["tfloc/relocalize/"], "summary": (
    "the project's own **global** localizer (no initial guess): a place index of virtual "
    "scans over the whole map (built once per map, cached on disk) searched by a "
    "heading-invariant turning-function and range signature plus a robust sector range "
    "profile, its best places resolved by `tf-plus`, ranked by `tf-plus`'s selection cost "
    "([docs/tf-global.md](tf-global.md))")}}
