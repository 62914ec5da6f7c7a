"""Write the tracking report of a measurement (scripts/track_measure.py) into its folder.

  .venv/bin/python scripts/track_report.py results/tracking [--no-figures]

Reads OUT/estimates.csv (or OUT/estimates.csv.gz), scores every (sequence, matcher) with tfloc.evaluation.trajectory and
writes OUT/tracking.md (tfloc.report.tracking: one table per sequence set) and
OUT/figures/tracking/*.png, plus OUT/scores.csv (one row per sequence and matcher).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("run", type=Path)
    ap.add_argument("--no-figures", action="store_true")
    ap.add_argument("--scenarios", type=Path, default=Path("data/scenarios"))
    args = ap.parse_args()

    import pandas as pd

    from tfloc.io.maps import load_map
    from tfloc.io.scenario import read_scenario
    from tfloc.report.tracking import sequence_scores, tracking_section

    path = args.run / "estimates.csv"
    if not path.exists():
        path = path.with_suffix(".csv.gz")
    df = pd.read_csv(path, keep_default_na=False, dtype=str)
    ds = {n: read_scenario(args.scenarios / n) for n in df["dataset"].unique()}
    maps = {} if args.no_figures else {n: load_map(s.map_path) for n, s in ds.items()}
    text = tracking_section(df, ds, maps, args.run, figures=not args.no_figures)
    (args.run / "tracking.md").write_text(text)
    sequence_scores(df, ds).drop(columns=["cpu_ms_all"]).to_csv(args.run / "scores.csv", index=False,
                                                               float_format="%.6g")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
