"""The files MRPT's ``pf-localization`` reads and writes, for :mod:`tfloc.baselines.mrpt_pf`.

* :func:`carmen_lines` — the sequence as a CARMEN log of ``ROBOTLASER1`` lines (each carries the
  scan with its start angle, field of view, resolution and maximum range, and the odometry pose),
  which MRPT's ``carmen2rawlog`` turns into an observations-only rawlog (an odometry observation
  and a 2D range scan per line). ``ROBOTLASER1`` rather than ``FLASER``: FLASER implies a 180°
  field of view, and two of the bundled lasers cover 179°. A range that is no return (not finite,
  ≤ 0 or ≥ the maximum range) is written as the maximum range.
* :func:`render_ini` — MRPT's shipped ``.ini`` with some ``key=value`` lines replaced (or added)
  section by section; every other line kept as shipped.
* :func:`parse_estimates` — the per-step ``PDF estimation: (x,y,phi deg), ESS (B.R.)= e
  tr(cov): s`` lines ``pf-localization`` logs (one per scan: ``MonteCarloLocalization_App.cpp``
  logs the particle set's mean after each filter step, 3 decimals in metres and 2 in degrees).

Units: metres, radians (degrees where MRPT's files use them, named ``_deg``).
"""

from __future__ import annotations

import math
import re

import numpy as np

from tfloc.core.laser import LaserSpec


def _num(v: float) -> str:
    return f"{v:.6f}".rstrip("0").rstrip(".") if math.isfinite(v) else "0"


def carmen_lines(laser: LaserSpec, ranges: list[np.ndarray], stamps: np.ndarray, odometry: np.ndarray) -> list[str]:
    """One ``ROBOTLASER1`` line per scan (laser and robot pose both the odometry pose, so the
    laser sits at the robot's origin); stamps in seconds."""
    out = []
    head = (f"ROBOTLASER1 0 {_num(laser.angle_min)} {_num(laser.fov)} {_num(laser.resolution)} "
            f"{_num(laser.max_range)} 0.01 0")
    for r, t, (x, y, th) in zip(ranges, stamps, odometry, strict=True):
        r = np.asarray(r, dtype=float)
        r = np.where(np.isfinite(r) & (r > 0) & (r < laser.max_range), r, laser.max_range)
        pose = f"{_num(x)} {_num(y)} {_num(th)}"
        out.append(f"{head} {len(r)} {' '.join(f'{v:.4f}' for v in r)} 0 {pose} {pose} 0 0 0 0 0 "
                   f"{t:.6f} tfloc {t:.6f}")
    return out


_SECTION = re.compile(r"^\s*\[([^\]]+)\]")
_KEY = re.compile(r"^\s*([A-Za-z0-9_]+)\s*=")


def render_ini(text: str, values: dict[tuple[str, str], object]) -> str:
    """``text`` (an ``.ini``) with the ``key=value`` line of each ``(section, key)`` of
    ``values`` replaced, or added at the section's end (the section added if missing)."""
    left = dict(values)
    out: list[str] = []
    section = None

    def flush(sec: str | None) -> None:
        for (s, k) in [sk for sk in left if sk[0] == sec]:
            out.append(f"{k}={_value(left.pop((s, k)))}")

    for line in text.splitlines():
        m = _SECTION.match(line)
        if m:
            flush(section)
            section = m.group(1).strip()
        else:
            k = _KEY.match(line)
            if k and (section, k.group(1)) in left:
                out.append(f"{k.group(1)}={_value(left.pop((section, k.group(1))))}")
                continue
        out.append(line)
    flush(section)
    for sec in dict.fromkeys(s for s, _ in left):
        out.append(f"[{sec}]")
        flush(sec)
    return "\n".join(out) + "\n"


def _value(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    return str(v)


_ESTIMATE = re.compile(r"PDF estimation: \(([^,]+),([^,]+),([^,)]+?)deg\).*?tr\(cov\):\s*(\S+)")


def parse_estimates(log: str) -> tuple[np.ndarray, np.ndarray]:
    """``(N, 3)`` poses (x, y metres; theta radians) and ``(N,)`` ``sqrt(trace(cov))`` of the
    particle set (MRPT's "tr(cov)": metres and radians mixed) from ``pf-localization``'s log."""
    poses, spread = [], []
    for m in _ESTIMATE.finditer(log):
        try:
            x, y, phi_deg, s = (float(g) for g in m.groups())
        except ValueError:
            x = y = phi_deg = s = math.nan
        poses.append((x, y, math.radians(phi_deg)))
        spread.append(s)
    return np.array(poses, dtype=float).reshape(-1, 3), np.array(spread, dtype=float)
