"""Which beam-angle reading makes a log's corrected scans line up best (FLASER stores no angles).

Method (consistency of the corrected scans with each other): split the scans into ``folds``
interleaved folds; for every return of a scan, take the distance to the nearest return of the
scans in the other folds (all at their corrected poses, under the candidate reading). A reading
that puts the beams at the wrong angles smears the map, so its distances are larger. The summary
is the mean of these distances clipped at ``clip`` metres (robust to unseen areas) and the
median; far returns (≥ ``far`` m) are reported separately because an angle error grows with range.
``python -m tfloc.datasets.spacing LOG`` prints the table of ``data/real/{intel,aces}/SPACING.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from tfloc.core.laser import LaserSpec


@dataclass(frozen=True)
class SpacingScore:
    """Alignment of one candidate reading (metres)."""

    label: str
    laser: LaserSpec
    mean_clipped: float
    median: float
    median_far: float
    n_points: int


def endpoints(ranges: np.ndarray, poses: np.ndarray, laser: LaserSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World endpoints ``(K, 2)`` of all returns, their scan index ``(K,)`` and range ``(K,)``."""
    ok = laser.valid(ranges)
    ang = poses[:, 2:3] + laser.angles[None, :]
    x = poses[:, 0:1] + ranges * np.cos(ang)
    y = poses[:, 1:2] + ranges * np.sin(ang)
    scan = np.broadcast_to(np.arange(len(poses))[:, None], ranges.shape)
    return np.column_stack((x[ok], y[ok])), scan[ok], ranges[ok]


def alignment(ranges: np.ndarray, poses: np.ndarray, laser: LaserSpec, label: str = "",
              folds: int = 5, clip: float = 0.5, far: float = 8.0) -> SpacingScore:
    """Cross-fold nearest-return distances of scans ``(N, n)`` at poses ``(N, 3)`` (see module doc)."""
    pts, scan, rng = endpoints(np.asarray(ranges, float), np.asarray(poses, float), laser)
    fold = scan % folds
    d = np.empty(len(pts))
    for k in range(folds):
        mine = fold == k
        d[mine] = cKDTree(pts[~mine]).query(pts[mine], k=1)[0]
    farm = rng >= far
    return SpacingScore(label, laser, float(np.minimum(d, clip).mean()), float(np.median(d)),
                        float(np.median(d[farm])) if farm.any() else float("nan"), int(len(d)))


def intel_candidates(max_range: float) -> dict[str, LaserSpec]:
    """The readings of a 180-beam FLASER scan over a 180° field of view (see data/real/README.md);
    used for the Intel and the ACES logs (``data/real/{intel,aces}/SPACING.md``)."""
    return {
        "1deg-from-90": LaserSpec.from_degrees(max_range, 179.0, 1.0, -90.0),
        "180/179deg": LaserSpec.from_degrees(max_range, 180.0, 180.0 / 179.0, -90.0),
        "1deg-centred": LaserSpec.from_degrees(max_range, 179.0, 1.0, -89.5),
    }


def compare(ranges: np.ndarray, poses: np.ndarray, candidates: dict[str, LaserSpec],
            folds: int = 5) -> list[SpacingScore]:
    """Scores of every candidate, best (smallest clipped mean) first."""
    out = [alignment(ranges, poses, las, name, folds) for name, las in candidates.items()]
    return sorted(out, key=lambda s: s.mean_clipped)


def main(argv: list[str] | None = None) -> None:
    """Print the candidates' scores for a corrected CARMEN log (its first ``--scans`` scans)."""
    import argparse

    from tfloc.datasets.real import ACES_NO_RETURN_M, NO_RETURN_M, clean_ranges
    from tfloc.io.carmen import read_carmen

    ap = argparse.ArgumentParser(prog="python -m tfloc.datasets.spacing", description=main.__doc__)
    ap.add_argument("log", help="a corrected CARMEN log, e.g. data/real/intel/intel-corrected.log.gz")
    ap.add_argument("--scans", type=int, default=0, help="only the first N scans (0: all)")
    ap.add_argument("--no-return", type=float, default=None,
                    help=f"range meaning no return (m; default {NO_RETURN_M}, ACES {ACES_NO_RETURN_M})")
    a = ap.parse_args(argv)
    no_return = a.no_return or (ACES_NO_RETURN_M if "aces" in a.log else NO_RETURN_M)
    log = read_carmen(a.log)
    lasers = log.lasers[:a.scans] if a.scans else log.lasers
    R = np.vstack([clean_ranges(s.ranges, no_return) for s in lasers])
    P = log.poses()[:len(lasers)]
    print("| reading | mean clipped (m) | median (m) | median ≥ 8 m (m) | returns |\n|---|---|---|---|---|")
    for sc in compare(R, P, intel_candidates(no_return)):
        print(f"| {sc.label} | {sc.mean_clipped:.4f} | {sc.median:.4f} | {sc.median_far:.4f} | {sc.n_points} |")


if __name__ == "__main__":
    main()
