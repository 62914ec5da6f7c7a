"""Bit-for-bit pins of compiled kernels that no oracle test compares exactly: each runs on fixed,
seeded inputs and the SHA-256 of its outputs must equal the digest recorded when the pin was
written. A mismatch means the kernel's arithmetic changed (or, on another machine, a libm whose
sin/cos round differently). ``TFLOC_PRINT_PINS=1 pytest -s tests/test_kernel_pins.py`` prints
the digests of the code as it is."""

from __future__ import annotations

import hashlib
import math
import os

import numpy as np
import pytest
from tfloc.baselines._corner_match import pair_hypotheses, search_hypotheses

from tfloc.maps._gridcast import carve_grid, raycast_grid
from tfloc.paper.corners import resample, resample_path
from tfloc.paper.turning import _match, _match_l1, turning_function
from tfloc.tfplus.kernels import (
    face_depths_kernel,
    field_pairs_kernel,
    refine_field_kernel,
    see_through_kernel,
)


def _digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def _resample() -> list:
    rng = np.random.default_rng(1)
    out = []
    for n in (1, 2, 5, 40):
        pts = np.cumsum(rng.normal(0.0, 0.4, (n, 2)), axis=0)
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
            a = np.sort(rng.uniform(0.0, 2 * math.pi, n))
            fs.append(turning_function(np.column_stack((np.cos(a), np.sin(a))) * rng.uniform(1, 3, (n, 1))))
        r, v = fs
        out.append(np.array(_match(r.breaks, r.angles, v.breaks, v.angles)))
        out.append(np.array(_match_l1(r.breaks, r.angles, v.breaks, v.angles)))
    return out


def _field_inputs():
    """A 30 × 40 lattice of 5 cm cells at (-0.3, -0.2) whose cells name the nearest of 50 map
    points (-1: none within 0.3 m), the points' unit normals and surface distances, a 60-point
    scan and 4 poses."""
    rng = np.random.default_rng(3)
    map_points = rng.uniform((-0.3, -0.2), (1.7, 1.3), (50, 2))
    cy, cx = np.mgrid[0:30, 0:40]
    centres = np.stack((-0.3 + 0.05 * (cx + 0.5), -0.2 + 0.05 * (cy + 0.5)), axis=-1)
    d = np.linalg.norm(centres[:, :, None, :] - map_points, axis=-1)
    nearest = np.where(d.min(axis=2) <= 0.3, d.argmin(axis=2), -1)
    a = rng.uniform(-math.pi, math.pi, 50)
    normals = np.column_stack((np.cos(a), np.sin(a)))
    plus, minus = rng.uniform(0.0, 0.1, 50), rng.uniform(0.0, 0.1, 50)
    points = rng.uniform(-1.0, 1.0, (60, 2))
    poses = np.column_stack((rng.uniform(0.3, 1.1, 4), rng.uniform(0.3, 0.8, 4), rng.uniform(-3, 3, 4)))
    return (nearest, -0.3, -0.2, 0.05, map_points, normals, plus, minus, points, poses)


def _field() -> list:
    f = _field_inputs()
    offsets = np.linspace(0.0, 0.03, 4)
    out = []
    for gate in (0.02, 0.1, 10.0):
        out.append(face_depths_kernel(*f, gate))
        out += field_pairs_kernel(*f, offsets, gate, 0.05, 0.5, 0.0)
        out += field_pairs_kernel(*f, offsets, gate, 0.05, 0.5, 1.0)
    poses, offsets = f[9].copy(), offsets.copy()
    started = refine_field_kernel(*f[:9], poses, offsets, np.array([0.5, 0.2, 0.1, 0.05]), 2, 0.1,
                                  True, 1.0, 1.0, 1e-6, 1.0, 0.025, 0.3, False)
    return out + [poses, offsets, np.array([started])]


def _occupied():
    rng = np.random.default_rng(4)
    occ = rng.random((25, 35)) < 0.04
    occ[:, 30:33] = True                                    # a thick wall
    occ[0, :] = occ[-1, :] = True
    poses = np.column_stack((rng.uniform(-0.2, 1.8, 6), rng.uniform(-0.2, 1.4, 6), rng.uniform(-3, 3, 6)))
    poses[0] = (0.5, 0.6, 0.0)                              # along a row
    poses[1] = (0.5, 0.6, math.pi / 2)                      # along a column
    return occ, poses, np.linspace(-math.pi, math.pi, 73)


def _grid() -> list:
    occ, poses, angles = _occupied()
    rng = np.random.default_rng(5)
    ranges = rng.uniform(0.0, 2.5, angles.size)
    ranges[::7], ranges[3::11] = np.inf, np.nan
    out = [raycast_grid(poses, angles, occ, -0.1, -0.05, 0.05, 2.0)]
    for margin in (0.0, 0.1):
        out.append(see_through_kernel(occ, -0.1, -0.05, 0.05, poses, angles, ranges, 2.0, margin))
    passes = np.zeros(occ.shape, dtype=np.int64)
    ends = rng.uniform(-5.0, 40.0, (200, 2))
    starts = rng.uniform(0.0, 30.0, (200, 2))
    starts[:3] = ends[:3]                                   # zero-length segments
    carve_grid(passes, starts, ends)
    return out + [passes]


def _corners() -> list:
    rng = np.random.default_rng(6)
    a = rng.uniform(0.0, 6.0, (14, 2))
    c, s = math.cos(0.2), math.sin(0.2)
    b = a @ np.array([[c, s], [-s, c]]) + (0.4, -0.3) + rng.normal(0.0, 0.01, a.shape)
    b = np.vstack((b[2:], rng.uniform(0.0, 6.0, (5, 2))))   # 2 corners lost, 5 spurious
    hyp = pair_hypotheses(a, b, 0.15, 0.5, math.radians(25), 4.0)
    out = [hyp.theta, hyp.t]
    for confidence, most in ((0.999, 5000), (1.0, 5000), (0.999, 40)):
        r = search_hypotheses(a, b, 0.15, 0.5, math.radians(25), 4.0, 0.2, confidence, most, seed=3)
        out.append(np.array([r.theta, *r.t, r.inliers, r.scored, r.drawn, r.pairs]))
    return out


CASES = {"resample": _resample, "turning": _turning, "field": _field, "grid": _grid,
         "corners": _corners}
PINS = {
    "resample": "4baa18eae9be598d",
    "turning": "e08a6bb6f69ceceb",
    "field": "2ffea6fb957490b4",
    "grid": "14f8c55883ef656a",
    "corners": "e34b60d255c8d108",
}


@pytest.mark.parametrize("name", CASES)
def test_kernel_outputs_are_pinned(name: str) -> None:
    got = _digest(*CASES[name]())
    if os.environ.get("TFLOC_PRINT_PINS"):
        print(f"{name}: {got}")
    assert got == PINS[name]
