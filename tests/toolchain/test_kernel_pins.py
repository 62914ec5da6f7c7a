"""Pins of compiled kernels that no oracle test compares exactly: each runs on fixed inputs and
its outputs must equal what was recorded when the pin was written.

The inputs are built only from arithmetic that rounds alike on every CPU: integers, their
quotients by powers of two, the four basic operations and ``sqrt`` elementwise, and ``math.*``
on Python floats. numpy's ``cos``, ``sin``, ``arctan2``, … ufuncs are not used to build them:
they take other SIMD paths at other CPU levels and round the last bit differently, so a pin of
their outputs would pin the CPU (``NPY_DISABLE_CPU_FEATURES`` shows it on any machine).

Two kinds of pin:

- ``DIGESTS``: SHA-256 of the outputs, bit for bit, for kernels whose arithmetic is the same on
  every CPU (numba code of basic operations, ``sqrt`` and libm's scalar functions);
- ``VALUES``: sums compared within a relative 1e-9, for outputs that pass through LAPACK
  (``np.linalg.solve`` in ``refine_field_kernel``: OpenBLAS picks its kernels by CPU,
  ``OPENBLAS_CORETYPE`` shows it) or through numpy's SIMD ``arctan2`` (the corner pairs'
  directions in :func:`~tfloc.baselines._corner_match.pair_hypotheses`).

``TFLOC_PRINT_PINS=1 pytest -s tests/toolchain/test_kernel_pins.py`` prints the pins of the code as it is.
``make test`` runs this file again with AVX-512 and with AVX2 disabled (``make test-cpu``)."""

from __future__ import annotations

import hashlib
import math
import os

import numpy as np
import pytest
from _tf_oracles import _match_l1, resample_path
from tfloc.baselines._corner_match import pair_hypotheses, search_hypotheses

from tfloc.maps._gridcast import carve_grid, raycast_grid
from tfloc.paper.corners import resample
from tfloc.paper.turning import _match, turning_function
from tfloc.tfplus.cost_kernel import see_through_kernel
from tfloc.tfplus.field_kernel import face_depths_kernel, field_pairs_kernel, refine_field_kernel

pytestmark = pytest.mark.bitwise


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def _sums(*arrays) -> list[float]:
    """Per array: its sum, its index-weighted sum and its sum of squares (NaN counted as 0): a
    change of any one value beyond round-off moves at least one of them."""
    out = []
    for a in arrays:
        a = np.nan_to_num(np.asarray(a, dtype=float).ravel())
        w = np.arange(1, a.size + 1) / max(a.size, 1)
        out += [float(a.sum()), float((w * a).sum()), float((a * a).sum())]
    return out


def _uniform(rng: np.random.Generator, low, high, shape) -> np.ndarray:
    """Uniform draws on a lattice of 2⁻²⁰ steps of [low, high): exact integers scaled by a power
    of two, then one product and one sum, which every CPU rounds alike."""
    u = rng.integers(0, 2 ** 20, shape) / 2.0 ** 20
    return np.asarray(low, dtype=float) + (np.asarray(high, dtype=float) - np.asarray(low, dtype=float)) * u


def _cos_sin(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin through ``math`` (libm), one Python float at a time."""
    return (np.array([math.cos(v) for v in np.ravel(a)]).reshape(np.shape(a)),
            np.array([math.sin(v) for v in np.ravel(a)]).reshape(np.shape(a)))


def _resample() -> list:
    rng = np.random.default_rng(1)
    out = []
    for n in (1, 2, 5, 40):
        pts = np.cumsum(_uniform(rng, -0.7, 0.7, (n, 2)), axis=0)
        pts[n // 2:n // 2 + 2] = pts[n // 2]                # a repeated point
        for spacing in (0.05, 0.3, 1.0):
            out += [resample(pts, spacing), resample_path(pts, spacing)]
    return out


def _turning() -> list:
    rng = np.random.default_rng(2)
    out = []
    for n_r, n_v in ((3, 3), (5, 8), (9, 6), (14, 14)):
        fs = []
        for n in (n_r, n_v):
            a = np.sort(_uniform(rng, 0.0, 2 * math.pi, n))
            c, s = _cos_sin(a)
            fs.append(turning_function(np.column_stack((c, s)) * _uniform(rng, 1, 3, (n, 1))))
        r, v = fs
        out.append(np.array(_match(r.breaks, r.angles, v.breaks, v.angles)))
        out.append(np.array(_match_l1(r.breaks, r.angles, v.breaks, v.angles)))
    return out


def _field_inputs():
    """A 30 × 40 lattice of 5 cm cells at (-0.3, -0.2) whose cells name the nearest of 50 map
    points (-1: none within 0.3 m), the points' unit normals and surface distances, a 60-point
    scan and 4 poses."""
    rng = np.random.default_rng(3)
    map_points = _uniform(rng, (-0.3, -0.2), (1.7, 1.3), (50, 2))
    cy, cx = np.mgrid[0:30, 0:40]
    centres = np.stack((-0.3 + 0.05 * (cx + 0.5), -0.2 + 0.05 * (cy + 0.5)), axis=-1)
    v = centres[:, :, None, :] - map_points
    d = np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1])
    nearest = np.where(d.min(axis=2) <= 0.3, d.argmin(axis=2), -1)
    normals = np.column_stack(_cos_sin(_uniform(rng, -math.pi, math.pi, 50)))
    plus, minus = _uniform(rng, 0.0, 0.1, 50), _uniform(rng, 0.0, 0.1, 50)
    points = _uniform(rng, -1.0, 1.0, (60, 2))
    poses = np.column_stack((_uniform(rng, 0.3, 1.1, 4), _uniform(rng, 0.3, 0.8, 4), _uniform(rng, -3, 3, 4)))
    return (nearest, -0.3, -0.2, 0.05, map_points, normals, plus, minus, points, poses)


def _field() -> list:
    f = _field_inputs()
    offsets = np.linspace(0.0, 0.03, 4)
    out = []
    for gate in (0.02, 0.1, 10.0):
        out.append(face_depths_kernel(*f, gate))
        out += field_pairs_kernel(*f, offsets, gate, 0.05, 0.5, 0.0)
        out += field_pairs_kernel(*f, offsets, gate, 0.05, 0.5, 1.0)
    return out


def _refine() -> list:
    f = _field_inputs()
    poses, offsets = f[9].copy(), np.linspace(0.0, 0.03, 4)
    started = refine_field_kernel(*f[:9], poses, offsets, np.array([0.5, 0.2, 0.1, 0.05]), 2, 0.1,
                                  True, 1.0, 1.0, 1e-6, 1.0, 0.025, 0.3, False)
    return [poses, offsets, np.array([started])]


def _occupied():
    rng = np.random.default_rng(4)
    occ = rng.integers(0, 100, (25, 35)) < 4
    occ[:, 30:33] = True                                    # a thick wall
    occ[0, :] = occ[-1, :] = True
    poses = np.column_stack((_uniform(rng, -0.2, 1.8, 6), _uniform(rng, -0.2, 1.4, 6), _uniform(rng, -3, 3, 6)))
    poses[0] = (0.5, 0.6, 0.0)                              # along a row
    poses[1] = (0.5, 0.6, math.pi / 2)                      # along a column
    return occ, poses, np.linspace(-math.pi, math.pi, 73)


def _grid() -> list:
    occ, poses, angles = _occupied()
    rng = np.random.default_rng(5)
    ranges = _uniform(rng, 0.0, 2.5, angles.size)
    ranges[::7], ranges[3::11] = np.inf, np.nan
    out = [raycast_grid(poses, angles, occ, -0.1, -0.05, 0.05, 2.0)]
    for margin in (0.0, 0.1):
        out.append(see_through_kernel(occ, -0.1, -0.05, 0.05, poses, angles, ranges, 2.0, margin))
    passes = np.zeros(occ.shape, dtype=np.int64)
    ends = _uniform(rng, -5.0, 40.0, (200, 2))
    starts = _uniform(rng, 0.0, 30.0, (200, 2))
    starts[:3] = ends[:3]                                   # zero-length segments
    carve_grid(passes, starts, ends)
    return out + [passes]


def _corner_sets() -> tuple[np.ndarray, np.ndarray]:
    """14 corners, and the same turned by 0.2 rad and moved, with 1 cm of noise, 2 of them lost
    and 5 spurious ones added."""
    rng = np.random.default_rng(6)
    a = _uniform(rng, 0.0, 6.0, (14, 2))
    c, s = math.cos(0.2), math.sin(0.2)
    b = np.column_stack((c * a[:, 0] - s * a[:, 1] + 0.4, s * a[:, 0] + c * a[:, 1] - 0.3))
    b = b + _uniform(rng, -0.01, 0.01, a.shape)
    return a, np.vstack((b[2:], _uniform(rng, 0.0, 6.0, (5, 2))))


def _corners() -> list:
    """The hypotheses (directions from numpy's arctan2: compared by ``VALUES``) and the adaptive
    searches' answers."""
    a, b = _corner_sets()
    hyp = pair_hypotheses(a, b, 0.15, 0.5, math.radians(25), 4.0)
    out = [hyp.theta, hyp.t]
    for confidence, most in ((0.999, 5000), (1.0, 5000), (0.999, 40)):
        r = search_hypotheses(a, b, 0.15, 0.5, math.radians(25), 4.0, 0.2, confidence, most, seed=3)
        out.append(np.array([r.theta, *r.t]))
    return out


def _corner_counts() -> list:
    """The adaptive searches' counts: inliers, hypotheses scored and drawn, pairs (integers)."""
    a, b = _corner_sets()
    out = []
    for confidence, most in ((0.999, 5000), (1.0, 5000), (0.999, 40)):
        r = search_hypotheses(a, b, 0.15, 0.5, math.radians(25), 4.0, 0.2, confidence, most, seed=3)
        out.append(np.array([r.inliers, r.scored, r.drawn, r.pairs], dtype=np.int64))
    return out


DIGESTS = {"resample": _resample, "turning": _turning, "field": _field, "grid": _grid,
           "corner-counts": _corner_counts}
VALUES = {"refine": _refine, "corners": _corners}
PINNED_DIGESTS = {
    "resample": "c324e537678d1938",
    "turning": "3e282707698aac05",
    "field": "649eee9b44575489",
    "grid": "1ff1311012a47e58",
    "corner-counts": "4cd61010b2879e98",
}
PINNED_VALUES: dict[str, list[float]] = {
    "refine": [7.029461792580705, 2.5071411824064573, 17.54688502968607, 0.17405812575593593,
               0.10374411623441068, 0.007860232412870006, 1.0, 1.0, 1.0],
    "corners": [21.453750782253714, 13.344688719597972, 14.087553856968295, -67.49963754851672,
                -24.30191720873829, 949.9743613763925, 0.30133980486222933, 0.034433842601234166,
                0.2911866801659929, 0.3024173680455813, 0.035367805644066275, 0.29017303525278926,
                0.30133980486222933, 0.034433842601234166, 0.2911866801659929],
}


@pytest.mark.parametrize("name", DIGESTS)
def test_kernel_outputs_are_pinned_bit_for_bit(name: str) -> None:
    got = _digest(*DIGESTS[name]())
    if os.environ.get("TFLOC_PRINT_PINS"):
        print(f'    "{name}": "{got}",')
    assert got == PINNED_DIGESTS[name]


@pytest.mark.parametrize("name", VALUES)
def test_kernel_outputs_are_pinned_within_round_off(name: str) -> None:
    got = _sums(*VALUES[name]())
    if os.environ.get("TFLOC_PRINT_PINS"):
        print(f'    "{name}": [{", ".join(repr(v) for v in got)}],')
    assert got == pytest.approx(PINNED_VALUES[name], rel=1e-9, abs=1e-12)


def test_the_inputs_do_not_pass_through_numpy_transcendentals(monkeypatch) -> None:
    """The pins' inputs are built without numpy's cos, sin, arctan2, hypot, exp or log, whose last
    bit depends on the CPU: with those ufuncs replaced by ones that raise, every input builds."""
    def refuse(*_a, **_k):
        raise AssertionError("a pinned input went through a numpy transcendental ufunc")

    for name in ("cos", "sin", "tan", "arctan2", "hypot", "exp", "log"):
        monkeypatch.setattr(np, name, refuse)
    _field_inputs(), _occupied(), _corner_sets()
