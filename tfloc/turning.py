"""Turning functions (Algorithm 4) and their matching (Sec. 4.3, Eq. 13).

A turning function Θ(s) gives, at arc length s ∈ [0, 1) of a polygon scaled to unit perimeter,
the direction of the edge there: the first edge's angle to the x axis, then plus each signed
turning angle (counter-clockwise positive). It is a step function; a convex counter-clockwise
polygon climbs by 2π over [0, 1).

Readings of Alg. 4: its per-vertex angle ``Vector(i)·Vector(i+1)`` is read as the turn from edge
i−1 to edge i (the literal indices skip the turn after the first edge and run past the last);
the angle of the scaled vectors is taken with ``atan2(cross, dot)``, which equals Eq. 11's
``arccos`` of unit vectors with Eq. 12's sign, and stays exact near 0 and π. The first edge's
cross product is read as ``V × Vector(1)`` so that its angle is counter-clockwise from x, as
the text says.

Matching (Sec. 4.3): the distance is Eq. 13's L2 norm ``(∫₀¹ |Θ_R − Θ_V − θ|² ds)^½`` (the "area
between the two graphs", with squared heights), minimised over the starting vertex of the
virtual polygon (a cyclic shift) and over a rotation offset θ. For a fixed shift the best θ is
the mean of ``Θ_R − Θ_V`` (Arkin et al. 1991), so the search over θ is exact and closed-form.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class TurningFunction:
    """A turning function: ``breaks`` (n+1,) from 0 to 1 and ``angles`` (n,) in radians,
    ``angles[i]`` holding on ``[breaks[i], breaks[i+1])``."""

    breaks: np.ndarray
    angles: np.ndarray

    @property
    def n_edges(self) -> int:
        return len(self.angles)

    def __call__(self, s: np.ndarray) -> np.ndarray:
        """Θ(s) for arc lengths ``s`` in [0, 1)."""
        idx = np.clip(np.searchsorted(self.breaks, s, side="right") - 1, 0, self.n_edges - 1)
        return self.angles[idx]


def turning_function(vertices: np.ndarray) -> TurningFunction:
    """Algorithm 4: the turning function of the closed polygon ``vertices`` ``(n, 2)`` (metres).

    Edges run ``v_i → v_{i+1}`` and ``v_n → v_1``; zero-length edges are dropped. Needs at least
    3 distinct vertices.
    """
    v = np.asarray(vertices, dtype=float)
    e = np.roll(v, -1, axis=0) - v
    length = np.hypot(e[:, 0], e[:, 1])
    e, length = e[length > 1e-12], length[length > 1e-12]
    if len(e) < 3:
        raise ValueError("a turning function needs a polygon with at least 3 edges")
    prev = np.roll(e, 1, axis=0)
    turn = np.arctan2(prev[:, 0] * e[:, 1] - prev[:, 1] * e[:, 0], np.einsum("ij,ij->i", prev, e))
    turn[0] = np.arctan2(e[0, 1], e[0, 0])
    breaks = np.concatenate(([0.0], np.cumsum(length))) / length.sum()
    breaks[-1] = 1.0
    return TurningFunction(breaks, np.cumsum(turn))


@dataclass(frozen=True)
class Match:
    """The best alignment of two turning functions.

    Attributes:
        distance: Eq. 13's Err (radians), ≥ 0.
        rotation: θ minimising it, in [-π, π): the real polygon is the virtual one rotated by
            this (radians).
        shift: the starting vertex of the virtual polygon that minimises it.
    """

    distance: float
    rotation: float
    shift: int


def match(real: TurningFunction, virtual: TurningFunction) -> Match:
    """Sec. 4.3: min over starting vertex (of ``virtual``) and rotation of the L2 distance."""
    n_v = virtual.n_edges
    starts = virtual.breaks[:n_v]                                 # (K,) arc length of each vertex
    moved = (virtual.breaks[None, :n_v] - starts[:, None]) % 1.0  # virtual breaks, re-started
    grid = np.sort(np.concatenate((np.broadcast_to(real.breaks, (n_v, len(real.breaks))), moved),
                                  axis=1), axis=1)
    width = np.diff(grid, axis=1)
    mid = 0.5 * (grid[:, 1:] + grid[:, :-1])
    u = mid + starts[:, None]
    wrapped = u >= 1.0
    d = real(mid) - (virtual(np.where(wrapped, u - 1.0, u)) + TWO_PI * wrapped)
    rot = np.einsum("ij,ij->i", width, d)
    err2 = np.einsum("ij,ij->i", width, d * d) - rot * rot
    k = int(np.argmin(err2))
    rotation = (float(rot[k]) + np.pi) % TWO_PI - np.pi
    return Match(float(np.sqrt(max(err2[k], 0.0))), rotation, k)
