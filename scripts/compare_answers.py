"""Compare the answers of two ``speed_timing.py`` runs (e.g. before/after a speed change):
per matcher, how many poses differ at all and the largest difference (metres, radians)::

    python scripts/compare_answers.py /tmp/before.csv /tmp/after.csv
"""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd


def main() -> None:
    a, b = (pd.read_csv(p, dtype={"est_x": str, "est_y": str, "est_theta": str})
            for p in sys.argv[1:3])
    m = a.merge(b, on=["dataset", "scan_id", "matcher"], suffixes=("_a", "_b"))
    for name, g in m.groupby("matcher"):
        same = ((g.est_x_a == g.est_x_b) & (g.est_y_a == g.est_y_b)
                & (g.est_theta_a == g.est_theta_b))
        dx = np.hypot(g.est_x_a.astype(float) - g.est_x_b.astype(float),
                      g.est_y_a.astype(float) - g.est_y_b.astype(float))
        dth = np.abs((g.est_theta_a.astype(float) - g.est_theta_b.astype(float) + np.pi)
                     % (2 * np.pi) - np.pi)
        print(f"{name}: {len(g)} scans, {int((~same).sum())} differ; max |Δxy| {dx.max():.3g} m, "
              f"max |Δθ| {dth.max():.3g} rad")


if __name__ == "__main__":
    main()
