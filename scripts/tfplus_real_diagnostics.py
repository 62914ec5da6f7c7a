"""Why ``tf-plus`` lost on real grid maps, measured at the *true* poses of the real scan-to-map logs.

For each dataset (and its map with walls thickened by ``--thicken`` cells, see
``scripts/tfplus_ablation_real.py``), at every scan's corrected pose:

* **virtual-scan bias**: the grid's ray-cast range minus the real range, over all beams where
  both have a return (a ray stops at the first occupied cell; a real return lies inside the wall);
* **wall thickness**: how thick the run of occupied cells through each occupied cell is along
  its normal (:func:`tfloc.maps.walls.run_extents`);
* **depth of the returns behind the wall surface** on the sensor's side, median per scan;
* **see-through beams at the truth**: the share of beams the selection cost counts as seen
  through a wall, by the rule before issue 15 (beyond the first occupied cell + 5 cm, or no
  return where the ray meets a wall) and by the rule now (beyond the far side of the first wall
  + 10 cm, or no return where the ray meets a wall);
* **where each refinement settles when started at the truth** (and at 4 offsets of 10 cm / 1°):
  the median distance from the truth and the share more than 10 cm off, for the refinement
  against virtual scans (before), against the occupied cells alone, and against the cells and
  the wall surfaces with the returns' depth (now).

Writes a markdown report to ``--out`` (default ``results/tf-plus-real-diagnostics.md``).

Run: ``OMP_NUM_THREADS=1 PYTHONPATH=$PWD python scripts/tfplus_real_diagnostics.py
[--datasets ...] [--thicken 0 1 2] [--limit-per-group 20]``
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from tfplus_ablation_real import DEV, ROOT, markdown, problems  # noqa: E402

from tfloc.maps.walls import run_extents  # noqa: E402
from tfloc.tfplus.cost import see_through  # noqa: E402
from tfloc.tfplus.matcher import TfPlusConfig, _field  # noqa: E402
from tfloc.tfplus.refine import face_depths, refine, refine_to_field  # noqa: E402

OFFSETS = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0175], [-0.07, 0.07, -0.0175],
                    [0.0, -0.1, -0.0175]])


def diagnose(name: str, thicken: int, limit_per_group: int) -> dict:
    """The measurements of the module docstring for one dataset and thickening."""
    probs = problems(name, limit_per_group, thicken)
    grid, laser = probs[0][2].map, probs[0][2].laser
    cfg = TfPlusConfig()
    field = _field(grid, cfg)
    T = np.array([t.as_array() for _, _, _, t in probs])
    R = np.vstack([p.ranges for _, _, p, _ in probs])
    V = grid.raycast(T, laser)
    ok = laser.valid(R) & laser.valid(V)
    bias = (V - R)[ok]
    plus, minus = run_extents(field.points, field.normals, grid.occupied, np.asarray(grid.origin),
                              grid.resolution, 0.3)
    thick = plus + minus + grid.resolution / 3.0
    old_rule, new_rule, depth = [], [], []
    drift: dict[str, list] = {"virtual scans (before)": [], "occupied cells": [], "cells + surfaces (now)": []}
    for (_, _, p, _), pose in zip(probs, T, strict=True):
        with np.errstate(invalid="ignore"):
            v = grid.raycast(pose, laser)
            real_ok = laser.valid(p.ranges)
            old_rule.append(np.mean(laser.valid(v) & ((real_ok & (p.ranges > v + 0.05)) | ~real_ok)))
        new_rule.append(np.mean(see_through(grid, laser, p.ranges, pose[None], 0.1)))
        d = face_depths(field, p.points, pose[None], 0.1)[0]
        depth.append(np.nanmedian(d) if np.isfinite(d).any() else np.nan)
        starts = pose[None, :] + OFFSETS
        rc = replace(cfg.refinement, prune_after=0)
        outs = {"virtual scans (before)": refine(grid, laser, p.points, starts, rc),
                "occupied cells": refine_to_field(field, p.points, starts, replace(rc, faces=False)),
                "cells + surfaces (now)": refine_to_field(field, p.points, starts, rc)}
        for k, o in outs.items():
            drift[k].append(np.hypot(o[:, 0] - pose[0], o[:, 1] - pose[1]))
    row = {"dataset": name.removeprefix("real-").replace("-scan-to-map", "") + (f"+{thicken}" if thicken else ""),
           "scans": len(probs),
           "virtual − real, median cm (IQR)": f"{100 * np.median(bias):.1f} ({100 * np.percentile(bias, 25):.1f} … "
                                              f"{100 * np.percentile(bias, 75):.1f})",
           "wall thickness, median cm (p75)": f"{100 * np.median(thick):.1f} ({100 * np.percentile(thick, 75):.1f})",
           "depth behind surface, median cm (IQR over scans)":
               f"{100 * np.nanmedian(depth):.1f} ({100 * np.nanpercentile(depth, 25):.1f} … "
               f"{100 * np.nanpercentile(depth, 75):.1f})",
           "see-through at truth, before %": 100 * float(np.mean(old_rule)),
           "see-through at truth, now %": 100 * float(np.mean(new_rule))}
    for k, v in drift.items():
        a = np.array(v)
        row[f"refine {k}: from truth cm"] = 100 * float(np.median(a[:, 0]))
        row[f"refine {k}: from offsets cm (> 10 cm %)"] = (f"{100 * np.median(a[:, 1:]):.2f} "
                                                           f"({100 * np.mean(a[:, 1:] > 0.1):.1f})")
    return row


def main() -> None:
    import pandas as pd

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", nargs="+", default=list(DEV))
    ap.add_argument("--thicken", nargs="*", type=int, default=[0, 1, 2])
    ap.add_argument("--limit-per-group", type=int, default=20)
    ap.add_argument("--out", type=Path, default=ROOT / "results/tf-plus-real-diagnostics.md")
    args = ap.parse_args()
    rows = [diagnose(n, k, args.limit_per_group) for n in args.datasets for k in args.thicken]
    for r in rows:
        print(r, flush=True)
    df = pd.DataFrame(rows).set_index("dataset").T.reset_index().rename(columns={"index": "measured at the true poses"})
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(
        "# tf-plus on real grid maps: measurements at the true poses\n\n"
        f"Command: `OMP_NUM_THREADS=1 PYTHONPATH=$PWD python scripts/tfplus_real_diagnostics.py --datasets "
        f"{' '.join(args.datasets)} --thicken {' '.join(map(str, args.thicken))} --limit-per-group "
        f"{args.limit_per_group}`. `+k`: the map's occupied cells dilated by k cells. See the script's "
        "docstring for what each row measures.\n\n" + markdown(df) + "\n")
    print(df.to_string(index=False))


if __name__ == "__main__":
    main()
