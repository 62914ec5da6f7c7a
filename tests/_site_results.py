"""A small results root for the site's tests: a single-scan run and a global run reported by
``tfloc report`` (so they have ``headline.csv``, ``report.md`` and, for the first, figures), a
tracking run with ``tracking.csv`` and a ``headline.csv`` written through the store (its rows
derived from the tracking scores below, no paired test) and a scaling study's ``slopes.csv``;
every other run of ``pages.toml`` is missing ("not yet run")."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from _estimates import row, synthetic_run, write_run

from tfloc.cli.report import make_report
from tfloc.core.rows.headline import HeadlineRow
from tfloc.evaluation.stats import wilson
from tfloc.io.table import write
from tfloc.io.tables import HEADLINE

TRACKING_CSV = """dataset,matcher,condition,n_scans,n_truth,distance_m,tracked,n_tracked,losses,recoveries,unrecovered,longest_lost_m,ape_rmse_m,ape_mean_m,ape_max_m,ape_rot_rmse_deg,ape_rot_max_deg,rpe_trans_m_per_m,rpe_rot_deg_per_m,cpu_ms_median,max_jump_m,jumps
real-a-native,tf-plus-track,real-native,100,50,10,0.98,49,0,0,0,0,0.03,0.02,0.1,0.5,1,0.04,0.5,0.7,0.5,0
real-a-native,csm-corr,real-native,100,50,10,0.96,48,0,0,0,0,0.03,0.02,0.1,0.5,1,0.04,0.5,17.0,0.5,0
real-a-native,amcl,real-native,100,50,10,0.2,10,3,3,0,1,0.15,0.1,0.4,3,9,0.1,2,0.03,0.2,0
real-b-native,tf-plus-track,real-native,80,40,8,1.0,40,0,0,0,0,0.02,0.02,0.1,0.5,1,0.04,0.5,0.9,0.5,0
real-b-native,csm-corr,real-native,80,40,8,0.8,32,2,2,0,5,2.0,1.0,9,20,90,1,6,20.0,4,9
real-b-native,amcl,real-native,80,40,8,0.1,4,5,5,0,9,0.2,0.15,0.5,4,10,0.1,2,0.04,0.2,0
"""

SLOPES_CSV = """axis,kind,matcher,slope,levels,ms_per_unit,first_ms,last_ms,first_size,last_size,grows
area,vector,tf-plus,-0.004,4,-2.5e-06,1.33,1.23,323.4,2.07e+04,False
area,vector,csm-corr,-0.043,4,-0.000146,22.6,17.3,323.4,2.07e+04,False
beams,vector,tf-plus,0.64,4,0.0024,1.08,3.51,181,1081,True
beams,vector,csm-corr,1.03,4,0.1019,17,108.7,181,1081,True
"""


def _global_run(path: Path, seed: int = 3) -> Path:
    rng = np.random.default_rng(seed)
    rows = []
    for d in ("global-office-1", "real-x-global"):
        for i in range(30):
            for m, p_ok in (("tf-global", 0.95), ("bnb-global", 0.6)):
                ok = rng.uniform() < p_ok
                rows.append(row(m, 0.01 if ok else 3.0, 0.3 if ok else 40.0, dataset=d, scan_id=f"{d}-{i:03d}",
                                runtime_s=float(rng.uniform(0.005, 0.05)), group="all"))
    declared = {d: {"mode": "global", "paper_scenarios": []} for d in ("global-office-1", "real-x-global")}
    write_run(path, rows, {d: str(path / "no-such-dir" / d) for d in declared}, declared)
    run = json.loads((path / "run.json").read_text())
    run["config"]["matchers"] = [{"label": m, "name": m, "params": {}} for m in ("tf-global", "bnb-global")]
    (path / "run.json").write_text(json.dumps(run))
    return path


def _native_headline(path: Path) -> None:
    """``headline.csv`` of the tracking run: each dataset's tracked share (Wilson interval) from
    :data:`TRACKING_CSV`, ranked, no paired test."""
    rows = [ln.split(",") for ln in TRACKING_CSV.strip().splitlines()[1:]]
    out = []
    for scope in dict.fromkeys(r[0] for r in rows):
        mine = sorted((r for r in rows if r[0] == scope), key=lambda r: -int(r[7]) / int(r[4]))
        for rank, r in enumerate(mine, 1):
            k, n = int(r[7]), int(r[4])
            lo, hi = wilson(k, n)
            out.append(HeadlineRow("sequence", scope, rank, r[1], "tracked", 100 * k / n, 100 * lo, 100 * hi, n,
                                   100 * float(r[12]), "APE RMSE", float(r[19]), "", "", float("nan")))
    write(path / HEADLINE.name, HEADLINE, out)


def results_root(root: Path) -> Path:
    """The results root under ``root`` (created); returns it."""
    root.mkdir(parents=True, exist_ok=True)
    make_report(synthetic_run(root / "paper-protocol"), None, with_figures=True)
    make_report(_global_run(root / "global-full"), None, with_figures=False)  # its datasets are not on disk
    native = root / "native"
    native.mkdir()
    (native / "tracking.csv").write_text(TRACKING_CSV)
    _native_headline(native)
    (native / "report.md").write_text("# native\n\nSee [the timing](timing.md) and [a missing file](nothing.csv).\n")
    (native / "run.json").write_text(json.dumps({"git": {"commit": "abc", "dirty": False}, "sessions": []}))
    (root / "scaling").mkdir()
    (root / "scaling" / "slopes.csv").write_text(SLOPES_CSV)
    return root
