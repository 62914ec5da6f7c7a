"""Routes a simulated robot drives through an office floor, and the trajectory it follows.

A route is a list of goals (room interiors, corridor ends). Between goals the path is the
shortest one on a 0.1 m grid of the map's free space (8-connected, ``scipy.sparse.csgraph``),
each step weighted up near walls so that it keeps to the middle of corridors and doorways, and
then shortened to straight legs that keep :data:`CLEARANCE_M` from all geometry. The robot
drives each leg straight at ``speed`` and turns in place between legs at ``turn_rate`` (a
differential-drive robot's way through doors and around corners). Units: metres, radians, s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from tfloc.core.pose import angdiff
from tfloc.errors import ConfigError
from tfloc.maps.vector import VectorMap

CELL_M = 0.1
#: the smallest distance from geometry of every point of a route (metres)
CLEARANCE_M = 0.3

#: goals (x, y) of the three bundled routes; valid on every office level (a goal that is not free
#: on a level is moved to the nearest free cell)
ROUTES: dict[str, tuple[tuple[float, float], ...]] = {
    "a": ((1.0, 7.5), (2.2, 3.0), (3.0, 7.5), (6.5, 11.5), (7.0, 7.5), (10.0, 2.0), (10.0, 7.5),
          (18.0, 11.5), (17.0, 7.5)),
    "b": ((19.0, 7.5), (18.5, 2.0), (17.0, 7.5), (13.5, 3.0), (13.0, 7.5), (14.0, 11.5),
          (11.0, 7.8), (10.0, 11.0), (5.0, 7.5), (2.5, 10.0), (1.0, 7.5)),
    "c": ((10.0, 1.0), (10.0, 7.5), (6.5, 4.5), (6.0, 7.5), (2.5, 12.0), (3.0, 7.5), (18.0, 13.0),
          (18.0, 7.5), (18.5, 2.0)),
}


@dataclass(frozen=True)
class Motion:
    """How the robot drives: ``speed`` (m/s) on legs, ``turn_rate`` (rad/s) in place."""

    speed: float = 1.0
    turn_rate: float = math.pi / 6

    def __post_init__(self) -> None:
        if not (self.speed > 0 and self.turn_rate > 0):
            raise ConfigError(f"speed and turn_rate must be > 0, got {self}")


def _grid(m: VectorMap) -> tuple[np.ndarray, np.ndarray, tuple[float, float]]:
    """Cell centres' free mask (clearance :data:`CLEARANCE_M`), distance to geometry (m), origin."""
    x0, y0, x1, y1 = m.bounds
    xs = np.arange(x0 + CELL_M / 2, x1, CELL_M)
    ys = np.arange(y0 + CELL_M / 2, y1, CELL_M)
    X, Y = np.meshgrid(xs, ys)
    xy = np.column_stack([X.ravel(), Y.ravel()])
    free0 = m.is_free(xy, 0.0).reshape(X.shape)
    free = m.is_free(xy, CLEARANCE_M).reshape(X.shape)
    dist = ndimage.distance_transform_edt(free0) * CELL_M
    return free, dist, (float(xs[0]), float(ys[0]))


def _cell(xy, origin, shape, free) -> tuple[int, int]:
    """The free cell nearest to ``xy`` (row, col)."""
    r = int(round((xy[1] - origin[1]) / CELL_M))
    c = int(round((xy[0] - origin[0]) / CELL_M))
    rr, cc = np.nonzero(free)
    k = int(np.argmin((rr - r) ** 2 + (cc - c) ** 2))
    return int(rr[k]), int(cc[k])


def _graph(free: np.ndarray, dist: np.ndarray):
    """The 8-connected graph of free cells, each step's length weighted by 1 + 0.3 m / distance."""
    h, w = free.shape
    idx = np.arange(h * w).reshape(h, w)
    cost = 1.0 + 0.3 / np.maximum(dist, CELL_M)
    rows, cols, vals = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        a = free[max(0, -dr):h - max(0, dr), max(0, -dc):w - max(0, dc)]
        b = free[max(0, dr):, max(0, dc):][:a.shape[0], :a.shape[1]] if dc >= 0 else \
            free[dr:, :w + dc][:a.shape[0], :a.shape[1]]
        ia = idx[max(0, -dr):h - max(0, dr), max(0, -dc):w - max(0, dc)]
        ib = (idx[max(0, dr):, max(0, dc):] if dc >= 0 else idx[dr:, :w + dc])[:a.shape[0], :a.shape[1]]
        ca = cost[max(0, -dr):h - max(0, dr), max(0, -dc):w - max(0, dc)]
        cb = (cost[max(0, dr):, max(0, dc):] if dc >= 0 else cost[dr:, :w + dc])[:a.shape[0], :a.shape[1]]
        ok = a & b
        length = math.hypot(dr, dc) * CELL_M
        rows.append(ia[ok])
        cols.append(ib[ok])
        vals.append(length * (ca[ok] + cb[ok]) / 2)
    r, c, v = (np.concatenate(x) for x in (rows, cols, vals))
    return coo_matrix((v, (r, c)), shape=(h * w, h * w)).tocsr()


def _visible(m: VectorMap, a: np.ndarray, b: np.ndarray) -> bool:
    n = max(2, int(math.ceil(np.linalg.norm(b - a) / 0.05)) + 1)
    pts = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
    return bool(m.is_free(pts, CLEARANCE_M).all())


def _shorten(m: VectorMap, path: np.ndarray) -> np.ndarray:
    """Greedy shortcuts: from each kept vertex, the farthest later vertex in straight sight."""
    out = [path[0]]
    i = 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1 and not _visible(m, path[i], path[j]):
            j -= 1
        out.append(path[j])
        i = j
    return np.array(out)


def plan_route(m: VectorMap, goals) -> np.ndarray:
    """The route through ``goals`` on ``m``: the vertices ``(K, 2)`` of its straight legs."""
    free, dist, origin = _grid(m)
    graph = _graph(free, dist)
    w = free.shape[1]
    cells = [_cell(g, origin, free.shape, free) for g in goals]
    pts: list[np.ndarray] = []
    for (ra, ca), (rb, cb) in zip(cells[:-1], cells[1:], strict=True):
        src, dst = ra * w + ca, rb * w + cb
        _, pred = dijkstra(graph, directed=False, indices=src, return_predecessors=True)
        if pred[dst] < 0 and dst != src:
            raise ConfigError(f"route: no free path from {goals[0]} to {goals[-1]} on {m.name}")
        chain = [dst]
        while chain[-1] != src:
            chain.append(int(pred[chain[-1]]))
        chain.reverse()
        xy = np.array([[origin[0] + (k % w) * CELL_M, origin[1] + (k // w) * CELL_M] for k in chain])
        pts.append(_shorten(m, xy) if not pts else _shorten(m, xy)[1:])
    verts = np.vstack(pts)
    keep = np.concatenate([[True], np.hypot(*np.diff(verts, axis=0).T) > 1e-9])
    return verts[keep]


def drive(verts: np.ndarray, motion: Motion, rate_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """Sample the robot's pose at ``rate_hz`` along the legs ``verts``: it starts facing the first
    leg, turns in place to each next leg's heading, drives each leg straight. Returns the stamps
    ``(N,)`` (s, from 0) and poses ``(N, 3)`` (world frame)."""
    heads = np.arctan2(np.diff(verts[:, 1]), np.diff(verts[:, 0]))
    lengths = np.hypot(*np.diff(verts, axis=0).T)
    # the motion as pieces (start pose, duration, kind) with kind "turn" (dθ) or "drive" (length)
    pieces = []
    for k, (h, length) in enumerate(zip(heads, lengths, strict=True)):
        if k > 0:
            dth = float(angdiff(h, heads[k - 1]))
            if abs(dth) > 1e-9:
                pieces.append(("turn", verts[k], heads[k - 1], dth, abs(dth) / motion.turn_rate))
        pieces.append(("drive", verts[k], h, length, length / motion.speed))
    ends = np.cumsum([p[4] for p in pieces])
    total = float(ends[-1])
    stamps = np.arange(0.0, total + 1e-9, 1.0 / rate_hz)
    poses = np.empty((len(stamps), 3))
    starts = ends - np.array([p[4] for p in pieces])
    which = np.minimum(np.searchsorted(ends, stamps, side="right"), len(pieces) - 1)
    for i, (t, j) in enumerate(zip(stamps, which, strict=True)):
        kind, xy, th, amount, dur = pieces[j]
        f = min(1.0, (t - starts[j]) / dur) if dur > 0 else 1.0
        if kind == "turn":
            poses[i] = (xy[0], xy[1], th + f * amount)
        else:
            poses[i] = (xy[0] + f * amount * math.cos(th), xy[1] + f * amount * math.sin(th), th)
    poses[:, 2] = np.arctan2(np.sin(poses[:, 2]), np.cos(poses[:, 2]))
    return stamps, poses
