"""Ground-truth relations files of Kümmerle et al. (2009), and joining them to a CARMEN log.

Line format, 8 whitespace-separated fields: ``t1 t2 dx dy dz droll dpitch dyaw``, the pose of the
robot at ``t2`` in the frame of the robot at ``t1`` (metres, radians); ``t1``/``t2`` are ipc
timestamps of the log's laser scans. Strict: errors name ``file:line``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from tfloc.core.pose import Pose
from tfloc.core.relation import Relation
from tfloc.errors import DatasetError, LogFormatError

from .carmen import LaserRecord
from .text import read_text

_FIELDS = ("t1", "t2", "dx", "dy", "dz", "droll", "dpitch", "dyaw")


def read_relations(path: str | Path) -> tuple[Relation, ...]:
    """Read a relations file; ``#`` comments and blank lines are skipped."""
    path = Path(path)
    out: list[Relation] = []
    text_ = read_text(path, LogFormatError, "relations file", latin1=True)
    for lineno, text in enumerate(text_.splitlines(), start=1):
        tok = text.split()
        if not tok or tok[0].startswith("#"):
            continue
        if len(tok) != len(_FIELDS):
            raise LogFormatError(f"{path}:{lineno}: {len(tok)} fields, expected {len(_FIELDS)} "
                                 f"({' '.join(_FIELDS)})")
        vals = []
        for name, s in zip(_FIELDS, tok, strict=True):
            try:
                v = float(s)
            except ValueError:
                raise LogFormatError(f"{path}:{lineno}: field {name} is not a number: {s!r}") from None
            if not math.isfinite(v):
                raise LogFormatError(f"{path}:{lineno}: field {name} is not finite: {s!r}")
            vals.append(v)
        t1, t2, dx, dy, _dz, _roll, _pitch, dyaw = vals
        out.append(Relation(t1, t2, Pose(dx, dy, dyaw), lineno))
    if not out:
        raise LogFormatError(f"{path}: no relations in the file")
    return tuple(out)


def join_relations(relations: Sequence[Relation], scans: Sequence[LaserRecord], path: str | Path = "",
                   tolerance: float = 5e-5) -> np.ndarray:
    """Index pairs ``(R, 2)`` of the scans at ``t1`` and ``t2`` of each relation.

    A timestamp matches the scan with the nearest ``timestamp`` within ``tolerance`` seconds
    (relations files print 5 decimals); a relation without a match raises, naming its line.
    """
    ts = np.array([s.timestamp for s in scans], dtype=float)
    order = np.argsort(ts, kind="stable")
    sorted_ts = ts[order]
    out = np.empty((len(relations), 2), dtype=np.int64)
    for k, rel in enumerate(relations):
        for j, t in enumerate((rel.t1, rel.t2)):
            i = int(np.clip(np.searchsorted(sorted_ts, t), 1, len(ts) - 1)) if len(ts) > 1 else 0
            cand = [c for c in (i - 1, i) if 0 <= c < len(ts)]
            best = min(cand, key=lambda c: abs(sorted_ts[c] - t))
            if abs(sorted_ts[best] - t) > tolerance:
                raise LogFormatError(f"{path}:{rel.line}: t{j + 1}={t:.5f} matches no scan of the log "
                                     f"(nearest {sorted_ts[best]:.5f})")
            out[k, j] = order[best]
    return out


def relations_path(scenario) -> Path | None:
    """The relations file a dataset names in ``scenario.json`` (``"relations"``, relative to the
    dataset directory), or ``None``."""
    rel = scenario.extra.get("relations")
    if rel is None:
        return None
    if not isinstance(rel, str) or not rel.strip():
        raise DatasetError(f"{scenario.root / 'scenario.json'}: field 'relations' must be a path (a string), "
                           f"got {rel!r:.60}")
    return scenario.root / rel
