"""Compiled ShortStraw pieces against copies of the previous numpy implementations (oracles)."""

from __future__ import annotations

import numpy as np
import pytest
from _tf_oracles import merge_lines
from numba import njit

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.maps.vector import VectorMap
from tfloc.paper.corners import _resample_into, corner_candidates, resample, shortstraw


# --- oracles: the implementations before the numba rewrite, verbatim -------------------------
@njit(cache=True)
def resample_ref(points, spacing):
    n = points.shape[0]
    out = np.empty((max(2, n) * 4 + 16, 2))
    if n == 0:
        return out[:0]
    m = 0
    p1x, p1y = points[0, 0], points[0, 1]
    out[m, 0], out[m, 1] = p1x, p1y
    m += 1
    i = 1
    while i < n:
        p2x, p2y = points[i, 0], points[i, 1]
        dx, dy = p2x - p1x, p2y - p1y
        d = np.sqrt(dx * dx + dy * dy)
        if d > spacing:
            p1x, p1y = p1x + dx / d * spacing, p1y + dy / d * spacing
            if m >= out.shape[0]:
                grown = np.empty((out.shape[0] * 2, 2))
                grown[:m] = out[:m]
                out = grown
            out[m, 0], out[m, 1] = p1x, p1y
            m += 1
        else:
            i += 1
    lx, ly = points[n - 1, 0] - p1x, points[n - 1, 1] - p1y
    if np.sqrt(lx * lx + ly * ly) > 0.5 * spacing:
        if m >= out.shape[0]:
            grown = np.empty((out.shape[0] + 1, 2))
            grown[:m] = out[:m]
            out = grown
        out[m, 0], out[m, 1] = points[n - 1, 0], points[n - 1, 1]
        m += 1
    return out[:m].copy()


def straws_ref(points, window=1):
    d = points[2 * window:] - points[:-2 * window]
    return np.einsum("ij,ij->i", d, d)


def corner_candidates_ref(points, window=1, t=0.99):
    n = len(points)
    if n <= 2 * window:
        return np.arange(n) if n < 2 else np.array([0, n - 1])
    s = straws_ref(points, window)
    below = np.flatnonzero(s < np.median(s) * t) + window
    return np.concatenate(([0], below, [n - 1]))


def merge_lines_ref(points, corners, threshold=0.95):
    seg = np.sqrt(((points[1:] - points[:-1]) ** 2).sum(axis=1))
    cum = np.zeros(points.shape[0])
    cum[1:] = np.cumsum(seg)
    keep = list(corners)
    i = 1
    while i < len(keep) - 1:
        a, b = keep[i - 1], keep[i + 1]
        path = cum[b] - cum[a]
        dx, dy = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1]
        if path > 0.0 and np.sqrt(dx * dx + dy * dy) / path > threshold:
            keep.pop(i)
        else:
            i += 1
    return np.array(keep, dtype=np.int64)


def shortstraw_ref(points, spacing, window=1, t=0.99, line_threshold=0.95):
    pts = np.ascontiguousarray(points, dtype=float)
    if len(pts) < 2:
        return pts.copy()
    res = resample_ref(pts, float(spacing))
    cand = corner_candidates_ref(res, window, t)
    return res[merge_lines_ref(res, cand.astype(np.int64), float(line_threshold))]
# ------------------------------------------------------------------------------------------------


def _polylines(seed: int, count: int):
    """Random walks with sharp and gentle turns, and real virtual scans of random rooms."""
    rng = np.random.default_rng(seed)
    laser = LaserSpec.lms200()
    for i in range(count):
        if i % 2:
            n = int(rng.integers(2, 200))
            heading = np.cumsum(rng.choice([0.0, 0.05, np.pi / 2, -np.pi / 3], n) * rng.random(n))
            step = rng.uniform(0.01, 0.5, (n, 1))
            yield np.cumsum(step * np.column_stack((np.cos(heading), np.sin(heading))), axis=0)
        else:
            a = rng.uniform(-6, 6, (int(rng.integers(4, 40)), 2))
            phi = rng.uniform(-np.pi, np.pi, len(a))
            ln = rng.uniform(0.3, 6, (len(a), 1))
            segs = np.hstack((a, a + ln * np.column_stack((np.cos(phi), np.sin(phi)))))
            segs = np.vstack((segs, [[-8, -8, 8, -8], [8, -8, 8, 8], [8, 8, -8, 8], [-8, 8, -8, -8]]))
            m = VectorMap.from_segments(segs)
            pts = laser.to_points(m.raycast(Pose(*rng.uniform(-5, 5, 2), rng.uniform(-3, 3)), laser))
            if len(pts) >= 2:
                yield pts


@pytest.mark.parametrize("spacing,window,t", [(1.0, 1, 0.99), (0.25, 1, 0.99), (0.1, 3, 0.99),
                                              (0.05, 2, 0.95), (0.5, 4, 1.0)])
def test_candidates_merge_and_shortstraw_match_oracles(spacing, window, t):
    checked = 0
    for pts in _polylines(int(spacing * 100) + window, 60):
        res = resample(pts, spacing)
        np.testing.assert_array_equal(res, resample_ref(pts, spacing))
        cand = corner_candidates(res, window, t)
        ref = corner_candidates_ref(res, window, t)
        np.testing.assert_array_equal(cand, ref)
        assert cand.dtype == np.int64
        for thr in (0.9, 0.95, 0.99):
            np.testing.assert_array_equal(merge_lines(res, ref.astype(np.int64), thr),
                                          merge_lines_ref(res, ref.astype(np.int64), thr))
        np.testing.assert_array_equal(shortstraw(pts, spacing, window, t, 0.95),
                                      shortstraw_ref(pts, spacing, window, t, 0.95))
        checked += len(cand) > 2
    assert checked > 20


def test_degenerate_inputs_match_oracles():
    for pts in (np.zeros((0, 2)), np.array([[0.0, 0.0]]), np.array([[0.0, 0.0], [0.1, 0.0]]),
                np.array([[0.0, 0.0], [3.0, 0.0]]), np.zeros((5, 2))):
        for window in (1, 3):
            np.testing.assert_array_equal(corner_candidates(pts, window), corner_candidates_ref(pts, window))
            np.testing.assert_array_equal(shortstraw(pts, 1.0, window), shortstraw_ref(pts, 1.0, window))


def test_resample_on_exact_spacings():
    """Points exactly ``spacing`` apart (the sqrt-free shortcut must not change the test d > S)."""
    for spacing in (1.0, 0.1, 0.3, 0.25):
        for n in (2, 5, 40):
            pts = np.column_stack((np.arange(n) * spacing, np.zeros(n)))
            np.testing.assert_array_equal(resample(pts, spacing), resample_ref(pts, spacing))
            diag = pts @ np.array([[np.cos(0.7), np.sin(0.7)], [-np.sin(0.7), np.cos(0.7)]])
            np.testing.assert_array_equal(resample(diag, spacing), resample_ref(diag, spacing))


def test_resample_into_counts_and_reports_overflow():
    pts = np.random.default_rng(0).uniform(0, 10, (50, 2))
    ref = resample_ref(pts, 0.3)
    assert _resample_into(pts, 0.3, np.empty((0, 2))) == len(ref)
    assert _resample_into(pts, 0.3, np.empty((len(ref) - 1, 2))) == -1
    out = np.empty((len(ref), 2))
    assert _resample_into(pts, 0.3, out) == len(ref)
    np.testing.assert_array_equal(out, ref)


def test_merge_lines_handles_short_corner_lists():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0]])
    for corners in ([0], [0, 3], [0, 1, 2, 3], [0, 2, 3]):
        c = np.array(corners, dtype=np.int64)
        np.testing.assert_array_equal(merge_lines(pts, c), merge_lines_ref(pts, c))


def test_walk_room_holds_every_walk() -> None:
    """The room the allocating walks take (walk_room: path / S + 2n + 16) is never short, for
    either walk, on random walks, zigzags with steps far below and far above S, and points
    scattered at random; the old 4n + 16 is short here."""
    from tfloc.paper.corners import _walk_into, walk_room

    rng = np.random.default_rng(26)
    short_at_4n = False
    for trial in range(240):
        n = int(rng.integers(2, 80))
        kind = trial % 3
        if kind == 0:
            pts = np.cumsum(rng.normal(scale=rng.uniform(0.01, 2.0), size=(n, 2)), axis=0)
        elif kind == 1:
            pts = np.column_stack((np.arange(n) * rng.uniform(0.001, 0.5),
                                   (np.arange(n) % 2) * rng.uniform(0.01, 3.0)))
        else:
            pts = rng.uniform(-5.0, 5.0, size=(n, 2))
        for spacing in (0.05, 0.3, 1.0):
            room = walk_room(pts, spacing)
            for along in (False, True):
                m = _walk_into(pts, spacing, along, np.empty((0, 2)))
                assert m <= room, (trial, spacing, along, m, room)
                short_at_4n |= m > 4 * n + 16
    assert short_at_4n


def test_a_walk_longer_than_4n_points_gives_the_references_corners():
    """Zigzags 9 m long at 0.1 m spacing walk ~90 points per input point, far beyond the 4n + 16
    the buffers held until walk_room sized them: the corners are the reference's, and
    scan_turning gives the turning function of those corners."""
    from tfloc.paper.corners import _walk_into
    from tfloc.paper.kernels import scan_turning
    from tfloc.paper.turning import _turning

    n = 21
    pts = np.column_stack((np.where(np.arange(n) % 2 == 0, 0.5, 9.5), np.linspace(0.0, 4.0, n)))
    assert _walk_into(pts, 0.1, False, np.empty((0, 2))) > 4 * n + 16
    np.testing.assert_array_equal(shortstraw(pts, 0.1, 1), shortstraw_ref(pts, 0.1, 1))
    ranges = np.hypot(pts[:, 0], pts[:, 1])
    directions = pts / ranges[:, None]
    vb, va = scan_turning(ranges, directions, 20.0, 0.1, 1, 0.99, 0.95, True, False)
    poly = np.vstack((np.zeros((1, 2)), shortstraw_ref(directions * ranges[:, None], 0.1, 1)))
    rb, ra = _turning(poly)
    assert len(va) >= 3
    np.testing.assert_array_equal(vb, rb)
    np.testing.assert_array_equal(va, ra)
