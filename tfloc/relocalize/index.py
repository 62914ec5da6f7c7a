"""The place index of a map: signatures of virtual scans from a lattice of free positions, built
once per map and laser, kept in memory per map object and on disk under the map's content hash.

Every free lattice position (``step`` metres apart, ``clearance`` from the walls) is seen at
``headings`` evenly spaced headings: a scanner with a field of view under 360° sees different
walls when it turns, so one signature per position cannot stand for all of them. Each entry
holds the scan's rotation-invariant signature (:mod:`tfloc.relocalize.signature`) and its range
profile (:mod:`tfloc.relocalize.profile`). A query finds the entries nearest the real scan by the
signature's Euclidean distance plus the weighted robust profile distance and returns the best
``count`` distinct places. The search is brute force (one matrix-vector product and one compiled
pass over the profiles): in 97 dimensions a KD-tree visits most of its leaves anyway, and the
profile's truncated distance is no metric a tree could use. The disk copy
(``<cache>/<sha256>.npz``) is keyed by the map's content (:func:`map_digest`: segments and mapped
area of a vector map, cells, resolution, origin and thresholds of a grid), the laser, the build
parameters and :data:`VERSION`: a changed map, laser or parameter builds a new index, and an
index is never read for a map it was not built from.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import shapely

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.maps.cache import cached
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap

from .profile import ProfileConfig, index_profiles
from .profile_kernel import place_distances
from .signature import SignatureConfig, signatures

#: Bumped when the index's content changes for the same inputs (old files are then not read).
VERSION = 2

#: Virtual scans ray-cast per batch while building (bounds the memory of a build).
BATCH = 4096


@dataclass(frozen=True)
class IndexConfig:
    """What the index holds (metres, radians).

    Attributes:
        step: spacing of the lattice of positions.
        headings: headings per position, evenly spaced from 0.
        clearance: a lattice position lies at least this far from the map's walls.
        signature: how a scan becomes its signature (:class:`SignatureConfig`).
        profile: the sectors of its range profile (:class:`ProfileConfig`).
    """

    RULES: ClassVar[dict] = {"> 0": ("step",), ">= 1": ("headings",), ">= 0": ("clearance",)}

    step: float = 0.35
    headings: int = 16
    clearance: float = 0.2
    signature: SignatureConfig = SignatureConfig()
    profile: ProfileConfig = ProfileConfig()


@dataclass(frozen=True, eq=False)
class PlaceIndex:
    """Signatures of the map's places.

    Attributes:
        poses: ``(N, 3)`` the virtual scans' poses (metres, radians).
        signatures: ``(N, D)`` their signatures.
        norms: ``(N,)`` their squared norms (for the distance by one product).
        profiles: ``(sectors, N)`` their range profiles (float32, fractions of the cap;
            sector-major for the query's pass over the entries).
        free_area_m2: the map's free area (m², counted on a 0.1 m lattice).
        build_cpu_s: CPU seconds the build took (0 if it was never built here: see ``loaded``).
        loaded: read from the disk cache rather than built.
        key: the content key (SHA-256, hex) it is stored under.
    """

    poses: np.ndarray
    signatures: np.ndarray
    norms: np.ndarray
    profiles: np.ndarray
    free_area_m2: float
    build_cpu_s: float
    loaded: bool
    key: str

    @property
    def nbytes(self) -> int:
        """Bytes in memory: poses, signatures, their norms and the profiles."""
        return int(self.poses.nbytes + self.signatures.nbytes + self.norms.nbytes
                   + self.profiles.nbytes)

    def distances(self, signature: np.ndarray, profiles: np.ndarray | None = None,
                  profile_weight: float = 0.0, truncation: float = 1.0) -> np.ndarray:
        """Distance ``(N,)`` of every entry to a query: the signatures' Euclidean distance, plus
        ``profile_weight`` times the robust profile distance to the query's shifted profiles
        ``(K, sectors)`` (:func:`~tfloc.relocalize.profile_kernel.place_distances`)."""
        sq = self.norms - 2.0 * (self.signatures @ signature) + float(signature @ signature)
        base = np.sqrt(np.maximum(sq, 0.0))
        if profiles is None or profile_weight <= 0.0:
            return base
        return place_distances(base, self.profiles, np.asarray(profiles, dtype=np.float32),
                               float(truncation), float(profile_weight))

    def query(self, signature: np.ndarray, count: int, separation: float,
              heading_separation: float, candidates: int = 8, profiles: np.ndarray | None = None,
              profile_weight: float = 0.0, truncation: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """The ``count`` nearest entries to the query (:meth:`distances`) that are distinct
        places: an entry is skipped if a better one lies within ``separation`` metres and
        ``heading_separation`` radians of it. Looks at ``candidates × count`` nearest entries.
        Returns entry indices (best first) and their distances."""
        k = int(min(len(self.poses), max(count, candidates * count)))
        if k == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0)
        d = self.distances(signature, profiles, profile_weight, truncation)
        idx = np.argpartition(d, k - 1)[:k] if k < len(d) else np.arange(len(d))
        idx = idx[np.argsort(d[idx], kind="stable")]
        dist = d[idx]
        keep: list[int] = []
        for n, i in enumerate(idx):
            p = self.poses[i]
            if any(abs(p[0] - self.poses[j][0]) <= separation
                   and abs(p[1] - self.poses[j][1]) <= separation
                   and abs((p[2] - self.poses[j][2] + np.pi) % (2 * np.pi) - np.pi) <= heading_separation
                   for j in idx[keep]):
                continue
            keep.append(n)
            if len(keep) == count:
                break
        return idx[keep], dist[keep]


def map_digest(map_: Map) -> str:
    """SHA-256 (hex) of what a map's ray casts and free space depend on."""
    h = hashlib.sha256(type(map_).__name__.encode())
    if isinstance(map_, GridMap):
        h.update(np.ascontiguousarray(map_.occupancy, dtype=np.float32).tobytes())
        h.update(np.array([map_.resolution, *map_.origin, map_.occupied_thresh, map_.free_thresh],
                          dtype=float).tobytes())
        h.update(repr(map_.shape).encode())
    elif isinstance(map_, VectorMap):
        h.update(np.ascontiguousarray(map_.segments, dtype=float).tobytes())
        h.update(shapely.to_wkb(map_.area))
        for g in map_.obstacles:
            h.update(shapely.to_wkb(g))
    else:
        pts, nrm = map_.sample_points(0.05)
        h.update(np.ascontiguousarray(pts, dtype=float).tobytes())
        h.update(np.array(map_.bounds, dtype=float).tobytes())
    return h.hexdigest()


def index_key(map_: Map, laser: LaserSpec, cfg: IndexConfig) -> str:
    """The content key of the index of ``map_`` seen by ``laser`` built with ``cfg``."""
    spec = {"version": VERSION, "map": map_digest(map_), "laser": asdict(laser), "index": asdict(cfg)}
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()


def default_cache_dir() -> Path:
    """``$TFLOC_INDEX_CACHE``, else ``$XDG_CACHE_HOME/tfloc/index`` (``~/.cache/tfloc/index``)."""
    env = os.environ.get("TFLOC_INDEX_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "tfloc" / "index"


def free_positions(map_: Map, step: float, clearance: float) -> np.ndarray:
    """Lattice positions ``(N, 2)`` (metres, ``step`` apart, cell centres of the map's bounds)
    in free space at least ``clearance`` from the walls."""
    x0, y0, x1, y1 = map_.bounds
    gx = np.arange(x0 + step / 2, x1, step)
    gy = np.arange(y0 + step / 2, y1, step)
    xx, yy = np.meshgrid(gx, gy)
    xy = np.column_stack((xx.ravel(), yy.ravel()))
    keep = map_.in_bounds(xy)
    keep[keep] = map_.is_free(xy[keep], clearance)
    return xy[keep]


def free_area(map_: Map, cell: float = 0.1) -> float:
    """The map's free area (m²), counted on a ``cell``-metre lattice."""
    return float(len(free_positions(map_, cell, 0.0)) * cell * cell)


def build_index(map_: Map, laser: LaserSpec, cfg: IndexConfig, key: str = "") -> PlaceIndex:
    """Ray-cast every lattice position × heading and compute the signatures (CPU time recorded)."""
    t0 = time.process_time()
    xy = free_positions(map_, cfg.step, cfg.clearance)
    heads = np.arange(cfg.headings) * (2 * np.pi / cfg.headings)
    heads = (heads + np.pi) % (2 * np.pi) - np.pi
    poses = np.column_stack((np.repeat(xy, len(heads), axis=0), np.tile(heads, len(xy))))
    sig = np.empty((len(poses), cfg.signature.size))
    prof = np.empty((cfg.profile.sectors, len(poses)), dtype=np.float32)
    for lo in range(0, len(poses), BATCH):
        ranges = np.atleast_2d(map_.raycast(poses[lo:lo + BATCH], laser))
        sig[lo:lo + BATCH] = signatures(ranges, laser, cfg.signature)
        prof[:, lo:lo + BATCH] = index_profiles(ranges, laser, cfg.profile).T
    area = free_area(map_)
    return PlaceIndex(poses, sig, np.einsum("ij,ij->i", sig, sig), prof, area,
                      time.process_time() - t0, False, key)


def _save(path: Path, index: PlaceIndex) -> None:
    """Write ``index`` to ``path`` atomically (a temporary file renamed into place)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "wb") as f:
        np.savez(f, poses=index.poses, signatures=index.signatures, profiles=index.profiles,
                 meta=np.array([index.free_area_m2, index.build_cpu_s]))
    os.replace(tmp, path)


def _load(path: Path, key: str) -> PlaceIndex | None:
    """The index stored at ``path``, or ``None`` if there is none or it cannot be read."""
    try:
        with np.load(path) as z:
            poses, sig, prof, meta = z["poses"], z["signatures"], z["profiles"], z["meta"]
    except (OSError, ValueError, KeyError, EOFError):
        return None
    if (poses.ndim != 2 or poses.shape[1] != 3 or len(sig) != len(poses) or len(poses) == 0
            or prof.ndim != 2 or prof.shape[1] != len(poses) or not np.isfinite(prof).all()):
        return None
    sig = np.ascontiguousarray(sig, dtype=float)
    prof = np.ascontiguousarray(prof, dtype=np.float32)
    return PlaceIndex(poses, sig, np.einsum("ij,ij->i", sig, sig), prof, float(meta[0]),
                      float(meta[1]), True, key)


def load_or_build(map_: Map, laser: LaserSpec, cfg: IndexConfig,
                  cache_dir: Path | None = None) -> PlaceIndex:
    """The index from ``cache_dir`` (default :func:`default_cache_dir`) if stored there under its
    key, else built and stored (a cache that cannot be written is skipped: the index is still
    returned)."""
    key = index_key(map_, laser, cfg)
    path = (cache_dir or default_cache_dir()) / f"{key}.npz"
    if path.exists():
        index = _load(path, key)
        if index is not None:
            return index
    index = build_index(map_, laser, cfg, key)
    try:
        _save(path, index)
    except OSError:
        pass
    return index


def place_index(map_: Map, laser: LaserSpec, cfg: IndexConfig, cache_dir: str = "",
                disk: bool = True) -> PlaceIndex:
    """The index of ``map_`` for ``laser`` and ``cfg``, once per map object in memory
    (:func:`tfloc.maps.cache.cached`), from or to the disk cache if ``disk``."""
    def build() -> PlaceIndex:
        if not disk:
            return build_index(map_, laser, cfg, index_key(map_, laser, cfg))
        return load_or_build(map_, laser, cfg, Path(cache_dir) if cache_dir else None)

    key: Any = ("tf-global-index", laser, cfg, cache_dir, disk)
    return cached(map_, key, build)
