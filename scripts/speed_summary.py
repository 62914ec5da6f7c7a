"""Markdown table of two ``speed_timing.py`` runs (before, after): per part (the paper protocol,
each real log) and matcher, the median CPU ms and its ratio to csm-corr's median in the same run
(ratios survive a loaded machine better than absolutes)::

    python scripts/speed_summary.py /tmp/before.csv /tmp/after.csv
"""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd


def medians(path: str) -> pd.DataFrame:
    df = pd.read_csv(path)
    df["part"] = np.where(df.dataset.str.startswith("real-"), df.dataset, "paper protocol")
    return df.groupby(["part", "matcher"]).agg(n=("cpu_ms", "size"), ms=("cpu_ms", "median"))


def main() -> None:
    before, after = medians(sys.argv[1]), medians(sys.argv[2])
    print("| part | matcher | n | before ms | after ms | after / before | before × csm-corr "
          "| after × csm-corr |")
    print("|---|---|---|---|---|---|---|---|")
    for (part, matcher), row in after.iterrows():
        b = before.loc[(part, matcher)]
        rb = b.ms / before.loc[(part, "csm-corr")].ms
        ra = row.ms / after.loc[(part, "csm-corr")].ms
        print(f"| {part} | {matcher} | {int(row.n)} | {b.ms:.2f} | {row.ms:.2f} | {row.ms / b.ms:.2f} "
              f"| {rb:.3f} | {ra:.3f} |")


if __name__ == "__main__":
    main()
