"""Scan-to-scan datasets from the MIT CSAIL log and the 1172 relations of Kümmerle et al. (2009).

Every row matches the scan at t2 (``ranges``) against the scan at t1 (``ref_ranges``, drawn as a
polyline map with the reference robot at the origin); ``true`` is the relation. Two initial-guess
protocols, written as two datasets and reported separately:

* ``real-csail-relations`` (**odometry**): ``init`` = the raw odometry between the two scans, as a
  SLAM front end would have it. For loop relations (revisits) it has drifted by metres, so that
  protocol measures the odometry as much as the matcher.
* ``real-csail-relations-perturbed`` (**perturbation**): ``init`` = the relation perturbed by the
  paper's seeded offsets (0–1, 1–2, 2–3 m × 0–5, 5–10, 10–15°, :mod:`tfloc.datasets.protocol`),
  the perturbation protocol of registration benchmarks: every relation, local or loop, tests the
  matcher, not the odometry.

``group`` is ``local`` (t2 − t1 ≤ 5 s) or ``loop``, with ``-no-overlap`` appended when the scans
barely overlap: fewer than half of the t2 scan's returns, placed at the true relation, fall in
the t1 scan's visibility polygon grown by 0.2 m (:func:`overlap`). Such relations cannot be
matched from the scans alone; they stay in the datasets and are reported apart.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import shapely

from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.io.carmen import read_carmen
from tfloc.io.relations import join_relations, read_relations
from tfloc.io.scenario import Scan, write_scenario
from tfloc.maps.scanmap import polyline_map_from_scan

from .protocol import DEFAULT_SEED, Perturbation, perturb
from .real import CSAIL_LASER, clean_ranges, front_scans

LOOP_GAP_S = 5.0
OVERLAP_MIN = 0.5
OVERLAP_MARGIN_M = 0.2


def overlap(ref_ranges: np.ndarray, ranges: np.ndarray, relation: Pose, laser: LaserSpec,
            margin: float = OVERLAP_MARGIN_M) -> float:
    """Share of the returns of ``ranges``, placed at ``relation`` in the reference frame, that lie
    in the visibility polygon of ``ref_ranges`` (sensor origin + returns, grown by ``margin`` m)."""
    ref = laser.to_points(ref_ranges)
    pts = relation.transform(laser.to_points(ranges))
    if len(ref) < 2 or len(pts) == 0:
        return 0.0
    seen = shapely.make_valid(shapely.Polygon(np.vstack(([0.0, 0.0], ref)))).buffer(margin)
    return float(shapely.contains_xy(seen, pts[:, 0], pts[:, 1]).mean())


def relation_scans(clf: Path, relations: Path, laser: LaserSpec) -> list[Scan]:
    """One row per relation (file order), ``scan_id`` = ``rel<line>``, ``init`` = odometry."""
    scans = front_scans(read_carmen(clf), laser)
    rels = read_relations(relations)
    rows = []
    for rel, (i, j) in zip(rels, join_relations(rels, scans, relations), strict=True):
        a, b = scans[i], scans[j]
        ref, cur = clean_ranges(a.ranges), clean_ranges(b.ranges)
        group = "local" if abs(rel.t2 - rel.t1) <= LOOP_GAP_S else "loop"
        if overlap(ref, cur, rel.delta, laser) < OVERLAP_MIN:
            group += "-no-overlap"
        rows.append(Scan(f"rel{rel.line:04d}", group, cur, a.odom.between(b.odom), rel.delta,
                         ref_ranges=ref))
    return rows


def perturbed(rows: list[Scan], laser: LaserSpec, cfg: Perturbation) -> list[Scan]:
    """The same relations with ``init`` drawn by the protocol's perturbation around the truth,
    inside each reference scan's mapped area and ``clearance_m`` from its walls."""
    truths = np.array([r.true.as_array() for r in rows])
    maps = [polyline_map_from_scan(r.ref_ranges, laser) for r in rows]
    init, _ = perturb(truths, maps, cfg)
    return [Scan(r.scan_id, r.group, r.ranges, Pose.from_array(p), r.true, ref_ranges=r.ref_ranges)
            for r, p in zip(rows, init, strict=True)]


_COMMON = (
    "Scan-to-scan on MIT CSAIL (Stata Center) with the 1172 ground-truth relations of Kümmerle et al. "
    "2009. Row = one relation (scan_id rel<line of mit-csail.relations>): ranges = FLASER scan at t2, "
    "ref_ranges = scan at t1, true = relation (pose at t2 in the frame at t1). The map is the reference "
    "scan (tfloc.io.scenario.map_for); the 'map' field names the source log only. group: local "
    f"(t2-t1 <= {LOOP_GAP_S:g} s) or loop (revisit), with '-no-overlap' where under {OVERLAP_MIN:.0%} of "
    "the t2 scan's returns at the true relation fall in the t1 scan's visibility polygon grown by "
    f"{OVERLAP_MARGIN_M:g} m. No-return 81.91 m -> inf; max_range 50 m (PARAM robot_front_laser_max "
    "50; largest real return 42.40 m). Note: in 534 relations the translation equals the odometry's to "
    "< 0.1 mm; most others differ from it by 5, 7.1 or 11.2 cm (5 cm x sqrt(k)), so the ground truth "
    "looks quantised at about 5 cm.")


def build_relations(real: Path, out: Path, seed: int = DEFAULT_SEED) -> list[Path]:
    """(Re)build both relations datasets (odometry and perturbation protocols) under ``out/scenarios``."""
    real, out = Path(real), Path(out)
    clf, rel = real / "mit-csail" / "mit-csail.clf.gz", real / "mit-csail" / "mit-csail.relations"
    source = {"files": ["data/real/mit-csail/mit-csail.clf.gz", "data/real/mit-csail/mit-csail.relations"],
              "provenance": "data/real/*/PROVENANCE.md"}
    rows = relation_scans(clf, rel, CSAIL_LASER)
    cfg = Perturbation(seed=seed)
    return [
        write_scenario(out / "scenarios" / "real-csail-relations", "real-csail-relations", clf,
                       CSAIL_LASER, rows, description=_COMMON + " Protocol (a), odometry: init = the raw "
                       "odometry between the two scans.", scan_to_scan=True, protocol="odometry",
                       source=source),
        write_scenario(out / "scenarios" / "real-csail-relations-perturbed", "real-csail-relations-perturbed",
                       clf, CSAIL_LASER, perturbed(rows, CSAIL_LASER, cfg),
                       description=_COMMON + " Protocol (b), perturbation: init = the relation perturbed "
                       "in the paper's 3x3 bins (0-1/1-2/2-3 m x 0-5/5-10/10-15 deg, balanced, seed "
                       f"{seed}) inside the reference scan's mapped area, >= {cfg.clearance_m:g} m from "
                       "its walls.", scan_to_scan=True, protocol="perturbation",
                       generator={"command": "tfloc real-data", "seed": seed,
                                  "clearance_m": cfg.clearance_m}, source=source),
    ]
