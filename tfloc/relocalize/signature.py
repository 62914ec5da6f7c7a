"""The place signature of a scan: a vector that does not change when the robot turns and changes
little when it moves a few decimetres, so that scans of one place lie near each other.

Blocks (each a distribution, so that scans of any beam count compare; the vector is their
concatenation, each block times its weight, compared by Euclidean distance):

* ``edges``: the magnitudes of the circular DFT (harmonics 1…``harmonics``, over the 0th) of the
  scan's length-weighted edge-direction histogram, the one ``tf-plus``'s heading seeds derive
  from the turning function (:func:`tfloc.tfplus.headings.edge_histogram`). Turning the robot
  shifts the histogram circularly, which leaves the magnitudes unchanged.
* ``turns``: the cumulative distribution of the turning function's turning angles (the jumps of
  Θ(s), which do not depend on the heading at all), each weighted by the shorter of its two edges.
* ``ranges``: the cumulative distribution of the ranges (metres, up to ``range_cap``) and the
  fraction of beams with no return: the room's extent. It is heading-invariant only as far as the
  field of view sees the same walls, which is why the index stores a few headings per place.

Cumulative distributions are compared in L2, a stand-in for the earth mover's distance: a small
shift of mass moves them a little, where a histogram's bins would jump. ``docs/tf-global.md``
has the measurements behind the blocks and weights.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.spatial.distance import pdist

from tfloc.core.laser import LaserSpec
from tfloc.paper.shape import ShapeConfig, scan_corners, scan_polygon
from tfloc.paper.turning import TurningFunction, turning_function
from tfloc.tfplus.headings import edge_histogram


@dataclass(frozen=True)
class SignatureConfig:
    """How a scan becomes its place signature (metres, radians; a field's meaning beside it)."""

    RULES: ClassVar[dict] = {
        ">= 0": ("edge_weight", "turn_weight", "range_weight", "length_weight", "pair_weight"),
        ">= 1": ("direction_bins", "harmonics", "turn_bins", "range_bins", "length_bins",
                 "pair_bins", "pair_points"),
        "> 0": ("direction_smoothing", "range_cap", "spacing")}

    edge_weight: float = 0.0  #: weight of the edge-direction spectrum block (0 leaves it out)
    turn_weight: float = 0.5  #: weight of the turning-angle distribution block
    range_weight: float = 1.0  #: weight of the range distribution block
    length_weight: float = 0.5  #: weight of the edge-length distribution block
    pair_weight: float = 1.0  #: weight of the point-pair distance (D2) block
    direction_bins: int = 72  #: bins of the edge-direction histogram over [0, 2π)
    direction_smoothing: float = float(np.radians(3.0))  #: its circular Gaussian smoothing (rad)
    harmonics: int = 12  #: DFT magnitudes kept (1…harmonics)
    turn_bins: int = 24  #: bins of the turning-angle distribution over [−π, π)
    range_bins: int = 20  #: bins of the range distribution over [0, range_cap]
    range_cap: float = 10.0  #: ranges beyond this (metres) count in the last bin
    length_bins: int = 16  #: bins of the edge-length distribution (log of the length)
    pair_bins: int = 24  #: bins of the pair distances over [0, 2·range_cap]
    pair_points: int = 60  #: scan points the pairs are drawn from, evenly spread
    spacing: float = 0.05  #: resampling distance of the scan's shape (metres; as tf-plus's seeds)

    @property
    def size(self) -> int:
        """Length of a signature vector."""
        return (self.harmonics + self.turn_bins + self.range_bins + 1 + self.length_bins
                + self.pair_bins)


def edge_spectrum(tf: TurningFunction | None, cfg: SignatureConfig) -> np.ndarray:
    """DFT magnitudes ``(harmonics,)`` of the edge-direction histogram over its mean (zeros for a
    degenerate scan): invariant to the heading."""
    if tf is None or tf.n_edges < 3:
        return np.zeros(cfg.harmonics)
    hist = edge_histogram(tf, cfg.direction_bins, cfg.direction_smoothing, True)
    spec = np.abs(np.fft.rfft(hist))
    out = np.zeros(cfg.harmonics)
    k = min(cfg.harmonics, len(spec) - 1)
    out[:k] = spec[1:k + 1] / max(spec[0], 1e-12)
    return out


def turn_distribution(tf: TurningFunction | None, cfg: SignatureConfig) -> np.ndarray:
    """Cumulative distribution ``(turn_bins,)`` of the turning angles between wall edges (the
    closure through the sensor left out), each weighted by the shorter of its two edges."""
    out = np.zeros(cfg.turn_bins)
    if tf is None or tf.n_edges < 5:
        return out
    lengths = np.diff(tf.breaks)[1:-1]
    turns = np.diff(tf.angles[1:-1])
    turns = (turns + np.pi) % (2 * np.pi) - np.pi
    w = np.minimum(lengths[:-1], lengths[1:])
    if w.sum() <= 0:
        return out
    idx = np.minimum(((turns + np.pi) / (2 * np.pi) * cfg.turn_bins).astype(np.int64), cfg.turn_bins - 1)
    return np.cumsum(np.bincount(idx, w, cfg.turn_bins)) / w.sum()


def range_distribution(ranges: np.ndarray, laser: LaserSpec, cfg: SignatureConfig) -> np.ndarray:
    """Cumulative distribution ``(range_bins,)`` of the returns' ranges over [0, range_cap] and
    the fraction of beams with no return (all as fractions of the beams)."""
    r = np.asarray(ranges, dtype=float)
    ok = laser.valid(r)
    idx = np.minimum((r[ok] / cfg.range_cap * cfg.range_bins).astype(np.int64), cfg.range_bins - 1)
    hist = np.bincount(idx, minlength=cfg.range_bins)[:cfg.range_bins] / max(len(r), 1)
    return np.concatenate((np.cumsum(hist), [1.0 - ok.mean()]))


def length_distribution(corners: np.ndarray, cfg: SignatureConfig) -> np.ndarray:
    """Cumulative distribution ``(length_bins,)`` of the scan polygon's wall edge lengths
    (metres, between consecutive corners, on a log scale from 0.1 m to ``range_cap``), weighted
    by length."""
    out = np.zeros(cfg.length_bins)
    if len(corners) < 2:
        return out
    lengths = np.hypot(*np.diff(corners, axis=0).T)
    if lengths.sum() <= 0:
        return out
    lo, hi = np.log(0.1), np.log(cfg.range_cap)
    pos = (np.log(np.maximum(lengths, 0.1)) - lo) / (hi - lo) * cfg.length_bins
    idx = np.clip(pos.astype(np.int64), 0, cfg.length_bins - 1)
    return np.cumsum(np.bincount(idx, lengths, cfg.length_bins)) / lengths.sum()


def pair_distribution(points: np.ndarray, cfg: SignatureConfig) -> np.ndarray:
    """Cumulative distribution ``(pair_bins,)`` of the distances between pairs of scan points
    (``pair_points`` of them, evenly spread over the returns; metres, up to 2 ``range_cap``): the
    D2 shape distribution of Osada et al. (2002), unchanged by any rotation."""
    out = np.zeros(cfg.pair_bins)
    if len(points) < 3:
        return out
    pts = points[np.linspace(0, len(points) - 1, min(cfg.pair_points, len(points))).astype(np.int64)]
    d = pdist(pts)
    idx = np.minimum((d / (2 * cfg.range_cap) * cfg.pair_bins).astype(np.int64), cfg.pair_bins - 1)
    return np.cumsum(np.bincount(idx, minlength=cfg.pair_bins)) / len(d)


def scan_signature(ranges: np.ndarray, laser: LaserSpec, cfg: SignatureConfig) -> np.ndarray:
    """The place signature ``(cfg.size,)`` of one scan (see the module notes)."""
    shape = ShapeConfig(spacing=cfg.spacing)
    corners = scan_corners(ranges, laser, shape)
    try:
        tf = turning_function(scan_polygon(corners, shape))
    except ValueError:
        tf = None
    blocks = [cfg.edge_weight * edge_spectrum(tf, cfg),
              cfg.turn_weight * turn_distribution(tf, cfg) / np.sqrt(cfg.turn_bins),
              cfg.range_weight * range_distribution(ranges, laser, cfg) / np.sqrt(cfg.range_bins),
              cfg.length_weight * length_distribution(corners, cfg) / np.sqrt(cfg.length_bins),
              cfg.pair_weight * pair_distribution(laser.to_points(ranges), cfg)
              / np.sqrt(cfg.pair_bins)]
    return np.concatenate(blocks)


def signatures(ranges: np.ndarray, laser: LaserSpec, cfg: SignatureConfig) -> np.ndarray:
    """Signatures ``(N, cfg.size)`` of ``(N, n_beams)`` scans."""
    r = np.atleast_2d(ranges)
    out = np.empty((len(r), cfg.size))
    for i in range(len(r)):
        out[i] = scan_signature(r[i], laser, cfg)
    return out
