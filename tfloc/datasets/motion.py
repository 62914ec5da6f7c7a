"""The odometry motion model (Thrun, Burgard, Fox, *Probabilistic Robotics*, 2005, Sec. 5.4) and
wheel slip: how simulated (and re-drawn real) odometry departs from the true motion.

A motion between two poses is decomposed as a rotation ``δrot1`` towards the new position, a
translation ``δtrans`` and a second rotation ``δrot2`` (Eq. 5.33–5.35). The sampler of Table 5.6
(``sample_motion_model_odometry``) perturbs each part with zero-mean Gaussian noise of variance

* ``δrot1``: α1·δrot1² + α2·δtrans²
* ``δtrans``: α3·δtrans² + α4·(δrot1² + δrot2²)
* ``δrot2``: α1·δrot2² + α2·δtrans²

(α1: rotation from rotation, α2: rotation from translation, α3: translation from translation,
α4: translation from rotation; the model AMCL's ``diff`` odometry uses). As in AMCL (Nav2's
``DifferentialMotionModel``), the rotations enter the variances as ``min(|δrot|, π − |δrot|)``,
so that driving backwards is as noisy as driving forwards (the book's formula would count a
backward step as a half turn). Here it draws the
*odometry* a robot would have measured from its *true* increments: the raw odometry pose is the
noisy increments composed from the start. A motion shorter than :data:`MIN_TRANS_M` is a turn in
place: ``δrot1`` = 0 (its heading would be undefined), as AMCL does.

Odometry is integrated at its own rate, not at the laser's: :func:`densify` cuts a trajectory
into steps of at most :data:`ODOM_STEP_M` and :data:`ODOM_STEP_RAD` (a 10 Hz odometry at 1 m/s
and 30°/s), and the noise is drawn on those steps, so that the odometry's error per metre does
not depend on how far apart the scans are (the model's variance grows with the square of a step:
drawn once per 1 m scan gap it would be ten times that of ten 0.1 m steps).

Wheel slip (:class:`Slip`) is a separate, labelled perturbation: at a few scans the robot moved
by 0.3–1 m more than the wheels say (it slid or was pushed), a jump the odometry does not see.
Units: metres, radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tfloc.core.pose import Pose, wrap_angle
from tfloc.errors import ConfigError

#: a motion shorter than this (metres) is a turn in place: δrot1 = 0
MIN_TRANS_M = 0.01
#: the longest odometry step (metres, radians): a 10 Hz odometry at 1 m/s and 30°/s
ODOM_STEP_M, ODOM_STEP_RAD = 0.1, math.radians(3.0)
ORIGIN = Pose()


@dataclass(frozen=True)
class OdometryNoise:
    """The four α of Table 5.6 (dimensionless variance ratios: rad²/rad², rad²/m², m²/m², m²/rad²)."""

    alpha1: float = 0.05
    alpha2: float = 0.05
    alpha3: float = 0.05
    alpha4: float = 0.05

    def __post_init__(self) -> None:
        if not all(math.isfinite(a) and a >= 0 for a in self.alphas):
            raise ConfigError(f"odometry noise α's must be finite and ≥ 0, got {self.alphas}")

    @property
    def alphas(self) -> tuple[float, float, float, float]:
        return (self.alpha1, self.alpha2, self.alpha3, self.alpha4)

    def to_dict(self) -> dict[str, float]:
        return {"alpha1": self.alpha1, "alpha2": self.alpha2, "alpha3": self.alpha3, "alpha4": self.alpha4}


@dataclass(frozen=True)
class Slip:
    """Wheel slip: with probability ``prob`` per scan the true motion exceeds the odometry by a
    translation of ``min_m``–``max_m`` metres in a uniformly random direction."""

    prob: float = 0.01
    min_m: float = 0.3
    max_m: float = 1.0

    def __post_init__(self) -> None:
        if not (0 <= self.prob <= 1 and 0 <= self.min_m <= self.max_m):
            raise ConfigError(f"slip needs 0 ≤ prob ≤ 1 and 0 ≤ min_m ≤ max_m, got {self}")

    def to_dict(self) -> dict[str, float]:
        return {"prob": self.prob, "min_m": self.min_m, "max_m": self.max_m}


def decompose(delta: Pose) -> tuple[float, float, float]:
    """``(δrot1, δtrans, δrot2)`` of a relative motion ``delta`` (robot frame of the start;
    Eq. 5.33–5.35); a turn in place (δtrans < :data:`MIN_TRANS_M`) has δrot1 = 0."""
    trans = math.hypot(delta.x, delta.y)
    rot1 = math.atan2(delta.y, delta.x) if trans >= MIN_TRANS_M else 0.0
    rot2 = float(wrap_angle(delta.theta - rot1))
    return rot1, trans, rot2


def recompose(rot1: np.ndarray | float, trans: np.ndarray | float,
              rot2: np.ndarray | float) -> np.ndarray:
    """Relative motions ``(N, 3)`` (x, y, θ in the start's frame) from their three parts."""
    rot1, trans, rot2 = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (rot1, trans, rot2)))
    return np.column_stack([np.atleast_1d(trans * np.cos(rot1)), np.atleast_1d(trans * np.sin(rot1)),
                            np.atleast_1d(wrap_angle(rot1 + rot2))])


def sample_parts(delta: Pose, noise: OdometryNoise, rng: np.random.Generator, n: int = 1) -> np.ndarray:
    """``n`` draws of the noisy parts ``(δ̂rot1, δ̂trans, δ̂rot2)`` of Table 5.6 for the motion
    ``delta``, ``(n, 3)``. Draws 3·n normals in a fixed order (reproducible)."""
    a1, a2, a3, a4 = noise.alphas
    rot1, trans, rot2 = decompose(delta)
    r1, r2 = _turn(rot1), _turn(rot2)
    z = rng.standard_normal((n, 3))
    return np.column_stack([
        rot1 - z[:, 0] * math.sqrt(a1 * r1 ** 2 + a2 * trans ** 2),
        trans - z[:, 1] * math.sqrt(a3 * trans ** 2 + a4 * (r1 ** 2 + r2 ** 2)),
        rot2 - z[:, 2] * math.sqrt(a1 * r2 ** 2 + a2 * trans ** 2)])


def _turn(rot: float) -> float:
    """The rotation as the noise sees it: forward and backward alike (AMCL)."""
    return min(abs(rot), math.pi - abs(rot))


def sample_increments(delta: Pose, noise: OdometryNoise, rng: np.random.Generator,
                      n: int = 1) -> np.ndarray:
    """``n`` draws of ``sample_motion_model_odometry`` (Table 5.6) for the motion ``delta``:
    ``(n, 3)`` noisy relative motions (x, y, θ in the start's frame)."""
    p = sample_parts(delta, noise, rng, n)
    return recompose(p[:, 0], p[:, 1], p[:, 2])


def draw_odometry(true_poses: np.ndarray, noise: OdometryNoise, rng: np.random.Generator,
                  slip: Slip | None = None, start: Pose = ORIGIN) -> tuple[np.ndarray, np.ndarray]:
    """Raw odometry ``(N, 3)`` for a trajectory of ``(N, 3)`` true poses (world frame): each true
    increment goes through :func:`sample_increments`, then (with ``slip``) a slip event removes a
    jump of ``slip.min_m``–``max_m`` metres from what the odometry saw. The odometry frame starts
    at ``start``. Returns the odometry poses and a boolean array marking slip scans."""
    P = np.asarray(true_poses, dtype=float)
    odom = [start]
    slipped = np.zeros(len(P), dtype=bool)
    for k in range(1, len(P)):
        delta = Pose.from_array(P[k - 1]).between(Pose.from_array(P[k]))
        inc = Pose.from_array(sample_increments(delta, noise, rng)[0])
        if slip is not None:
            u, dist, ang = rng.random(), rng.uniform(slip.min_m, slip.max_m), rng.uniform(-math.pi, math.pi)
            if u < slip.prob:
                slipped[k] = True
                inc = Pose(inc.x - dist * math.cos(ang), inc.y - dist * math.sin(ang), inc.theta)
        odom.append(odom[-1].compose(inc))
    return np.array([p.as_array() for p in odom]), slipped


def densify(poses: np.ndarray, step_m: float = ODOM_STEP_M,
            step_rad: float = ODOM_STEP_RAD) -> tuple[np.ndarray, np.ndarray]:
    """The trajectory ``poses`` ``(N, 3)`` with every gap driven as a differential-drive robot
    does it in the model's terms: turn in place by ``δrot1``, drive straight ``δtrans``, turn by
    ``δrot2`` (a gap whose motion points backwards is driven backwards, as AMCL reads it), each
    cut into equal steps of at most ``step_m`` and ``step_rad``. Returns the dense poses and the
    index of each original pose in them."""
    P = np.asarray(poses, dtype=float)
    out, idx = [P[:1]], [0]
    for a, b in zip(P[:-1], P[1:], strict=True):
        d = Pose.from_array(a).between(Pose.from_array(b))
        rot1, trans, rot2 = decompose(d)
        if abs(rot1) > math.pi / 2:  # backwards
            rot1, trans = float(wrap_angle(rot1 + math.pi)), -trans
            rot2 = float(wrap_angle(d.theta - rot1))
        x, y, th = (float(v) for v in a)
        pts: list[tuple[float, float, float]] = []
        n = math.ceil(abs(rot1) / step_rad - 1e-9)
        pts += [(x, y, th + f * rot1) for f in np.arange(1, n + 1) / max(n, 1)]
        th += rot1
        n = math.ceil(abs(trans) / step_m - 1e-9)
        c, s_ = math.cos(th), math.sin(th)
        pts += [(x + f * trans * c, y + f * trans * s_, th) for f in np.arange(1, n + 1) / max(n, 1)]
        x, y = x + trans * c, y + trans * s_
        n = math.ceil(abs(rot2) / step_rad - 1e-9)
        pts += [(x, y, th + f * rot2) for f in np.arange(1, n + 1) / max(n, 1)]
        seg = np.array(pts or [tuple(b)], dtype=float)
        seg[-1] = b
        out.append(seg)
        idx.append(idx[-1] + len(seg))
    dense = np.vstack(out)
    dense[:, 2] = wrap_angle(dense[:, 2])
    return dense, np.array(idx)
