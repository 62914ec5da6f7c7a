"""TUM trajectory files: one pose per line, ``timestamp x y z qx qy qz qw`` (s, m, unit quaternion).

This is the format of the TUM RGB-D benchmark that ``evo`` (``evo_ape tum ...``) and most SLAM
evaluation tools read. Planar poses are written with ``z = qx = qy = 0``, ``qz = sin(θ/2)``,
``qw = cos(θ/2)``; reading keeps x, y and the yaw of the quaternion.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tfloc.errors import LogFormatError

from .text import read_text

HEADER = "# timestamp x y z qx qy qz qw"


def write_tum(path: str | Path, stamps: np.ndarray, poses: np.ndarray) -> Path:
    """Write ``stamps`` ``(N,)`` (s) and planar ``poses`` ``(N, 3)`` (m, m, rad) as a TUM file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    t = np.asarray(stamps, dtype=float).reshape(-1)
    p = np.asarray(poses, dtype=float).reshape(-1, 3)
    half = 0.5 * p[:, 2]
    lines = [HEADER] + [f"{ti:.6f} {x:.9f} {y:.9f} 0 0 0 {qz:.12f} {qw:.12f}"
                        for ti, x, y, qz, qw in zip(t, p[:, 0], p[:, 1], np.sin(half), np.cos(half),
                                                    strict=True)]
    path.write_text("\n".join(lines) + "\n")
    return path


def read_tum(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Read a TUM file into stamps ``(N,)`` (s) and planar poses ``(N, 3)`` (x, y, yaw).

    Blank lines and ``#`` comments are skipped; every other line needs eight numbers and a
    non-zero quaternion."""
    path = Path(path)
    text = read_text(path, LogFormatError, "TUM trajectory file")
    stamps, poses = [], []
    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.replace(",", " ").split()
        if len(parts) != 8:
            raise LogFormatError(f"{path}:{n}: expected 8 fields (timestamp x y z qx qy qz qw), got {len(parts)}")
        try:
            t, x, y, _z, qx, qy, qz, qw = (float(v) for v in parts)
        except ValueError:
            raise LogFormatError(f"{path}:{n}: a field is not a number: {line!r}") from None
        if not np.isfinite([t, x, y, qx, qy, qz, qw]).all() or qx * qx + qy * qy + qz * qz + qw * qw == 0:
            raise LogFormatError(f"{path}:{n}: non-finite value or zero quaternion")
        stamps.append(t)
        poses.append((x, y, float(quaternion_yaw(qx, qy, qz, qw))))
    return np.array(stamps, dtype=float), np.array(poses, dtype=float).reshape(-1, 3)


def quaternion_yaw(qx, qy, qz, qw):
    """Yaw (rad) of quaternions (any non-zero norm; scalars or arrays): the heading of the
    rotated x axis projected on the xy plane."""
    qx, qy, qz, qw = (np.asarray(v, dtype=float) for v in (qx, qy, qz, qw))
    return np.arctan2(2.0 * (qw * qz + qx * qy), qw * qw + qx * qx - qy * qy - qz * qz)
