"""A scan as a shape: its ShortStraw corners (Algs. 1–3), its closed polygon and its turning
function (Alg. 4) — the representation the paper's method compares, shared by ``tf``, ``tf-best``,
``tf-plus``'s heading seeds and ``cv-corners``.

Readings (the text is ambiguous or wrong; each choice is the one that works, see the fields of
:class:`ShapeConfig`): the scan polygon is closed through the sensor origin, and no-return beams
are dropped and their neighbours joined (a dropout then changes the polygon by one short chord;
clipping to max range would add a spurious arc).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.errors import ParameterError

from .corners import shortstraw
from .turning import TurningFunction, turning_function

_ORIGIN = np.zeros((1, 2))
_RESAMPLINGS = ("chord", "path")


@dataclass(frozen=True)
class ShapeConfig:
    """How a scan becomes a polygon; defaults are the paper's values and literal readings.

    Attributes:
        spacing: S of Alg. 1, the resampling distance, in **metres**. Alg. 1 sets "S ← 1" without
            a unit, and "P3 is located exactly S Euclidian distance away from the P1"; the data
            are in metres (the LMS200's "range of 10 m"), so the literal value is 1 m. Algs. 1
            and 3 square their distances, which is self-consistent only at S = 1 (see
            :mod:`tfloc.paper.corners` for how the squares are read), so other values are a reading.
        window: w of Alg. 2 ("ω is a static window with a length of one (ω=1)"; ShortStraw's
            authors use 3).
        straw_t: t of Alg. 2 (0.99).
        line_threshold: Is-Line threshold of Alg. 3 (0.95).
        resampling: how Alg. 1 steps: ``"chord"`` (its formula ``P3 ← P1 + (P2 − P1)/D·S``, from
            the last emitted point towards the next input point; default) or ``"path"`` (its
            sentence "P3 is located exactly S Euclidian distance away from the P1 in the slop
            direction of the straight line from P(i−1) to P(i)", read as the original
            ShortStraw's walk along the path through P(i−1), P(i)).
        close_through_origin: how the scan polygon is closed. Alg. 4 closes it from the last
            corner to the first ("if i = Corners then Vector(i) ← Corners(1) − Corners(i)",
            ``False``); ``True`` (default) closes it through the sensor origin, which keeps the
            polygon of a 180° scan simple and counter-clockwise ("Vectors are create in
            counterclockwise direction").
    """

    spacing: float = 1.0
    window: int = 1
    straw_t: float = 0.99
    line_threshold: float = 0.95
    resampling: str = "chord"
    close_through_origin: bool = True

    def __post_init__(self) -> None:
        if self.resampling not in _RESAMPLINGS:
            raise ParameterError(f"resampling must be one of {_RESAMPLINGS}, not {self.resampling!r}", ("resampling",))
        if not self.spacing > 0:
            raise ParameterError(f"spacing must be > 0 metres, not {self.spacing!r}", ("spacing",))


def scan_corners(ranges: np.ndarray, laser: LaserSpec, shape: ShapeConfig = ShapeConfig()) -> np.ndarray:
    """ShortStraw corners of one scan, ``(K, 2)`` in the sensor frame (metres).

    No-return beams are dropped and their neighbours joined (see module notes).
    """
    pts = laser.to_points(ranges)
    if shape.resampling == "path":
        return shortstraw(pts, shape.spacing, shape.window, shape.straw_t, shape.line_threshold,
                          along_path=True)
    return shortstraw(pts, shape.spacing, shape.window, shape.straw_t, shape.line_threshold)


def scan_polygon(corners: np.ndarray, shape: ShapeConfig = ShapeConfig()) -> np.ndarray:
    """The closed scan polygon of a scan's corners (through the sensor origin if configured)."""
    if shape.close_through_origin:
        return np.concatenate((_ORIGIN, corners))
    return corners


def scan_turning_function(ranges: np.ndarray, laser: LaserSpec,
                          shape: ShapeConfig = ShapeConfig()) -> TurningFunction | None:
    """Turning function of a scan, or ``None`` if its polygon is degenerate (< 3 edges)."""
    try:
        return turning_function(scan_polygon(scan_corners(ranges, laser, shape), shape))
    except ValueError:
        return None
