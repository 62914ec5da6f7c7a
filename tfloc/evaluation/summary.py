"""The paper's scenarios and the run summary (``summary.csv``): metrics per matcher × grouping.

Which datasets pose which of the paper's scenarios is what each declares in its
``scenario.json`` (``"paper_scenarios"``, :func:`tfloc.io.scenario.paper_scenarios_of`; the
mapping ``paper`` below, dataset → scenarios), never its name: Scenario I = every dataset that
declares ``I`` (one sample each); Scenario II = a dataset declaring ``II`` binned by initial angle
offset; Scenario III = one declaring ``III`` binned by initial distance offset. Other datasets
get per-dataset rows, binned by distance and angle offset when they are scan-to-map (a
scan-to-scan dataset's offsets are odometry, not bins).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

import pandas as pd

from .metrics import METRIC_COLUMNS, summarize

SUMMARY_KEYS = ["grouping", "dataset", "bin", "matcher"]
Paper = Mapping[str, Sequence[str]]


def declaring(paper: Paper, scenario: str) -> list[str]:
    """The datasets that declare ``scenario`` (sorted)."""
    return sorted(d for d, s in paper.items() if scenario in s)


def scenario_rows(p: pd.DataFrame, paper: Paper) -> pd.DataFrame:
    """Prepared rows labelled by paper scenario (``scenario``: I/II/III), ``sample`` and the
    dataset they come from. A dataset declaring II and III appears twice (by angle bin, by
    distance bin)."""
    parts = []
    one = p[p["dataset"].isin(declaring(paper, "I"))]
    if len(one):
        parts.append(one.assign(scenario="I", sample=one["dataset"]))
    for name, col in (("II", "angle_bin"), ("III", "dist_bin")):
        pool = p[p["dataset"].isin(declaring(paper, name))]
        if len(pool):
            parts.append(pool.assign(scenario=name, sample=pool[col].astype(object)))
    if not parts:
        return p.iloc[:0].assign(scenario=pd.Series(dtype=object), sample=pd.Series(dtype=object))
    return pd.concat(parts, ignore_index=True)


def scenario_summary(p: pd.DataFrame, paper: Paper) -> pd.DataFrame:
    """Metrics per (scenario, sample, matcher), samples in table order, missing bins dropped;
    ``dataset``: the dataset of a Scenario I sample, or the binned dataset(s) of II and III."""
    s = scenario_rows(p, paper)
    if s.empty:
        return pd.DataFrame(columns=["scenario", "sample", "matcher", "dataset", *METRIC_COLUMNS])
    s = s[s["sample"].notna()]
    out = summarize(s, ["scenario", "sample", "matcher"])
    origin = s.groupby(["scenario", "sample"], observed=True)["dataset"].agg(lambda d: "+".join(sorted(set(d))))
    out["dataset"] = [origin[(a, b)] for a, b in zip(out["scenario"], out["sample"], strict=True)]
    order = {k: i for i, k in enumerate([*declaring(paper, "I"), *p["angle_bin"].cat.categories,
                                         *p["dist_bin"].cat.categories])}
    out["_o"] = out["sample"].map(order)
    return out.sort_values(["scenario", "_o", "matcher"]).drop(columns="_o").reset_index(drop=True)


def summary_table(p: pd.DataFrame, scan_to_scan: Iterable[str] = (), paper: Paper | None = None) -> pd.DataFrame:
    """Every grouping of the report in one long table (columns :data:`SUMMARY_KEYS` + metrics).

    groupings: ``scenario-I`` (bin = all), ``scenario-II`` (bin = angle bin), ``scenario-III``
    (bin = distance bin), ``dataset`` (bin = all), ``dataset-dist_bin``, ``dataset-angle_bin``
    (scan-to-map datasets with truth), ``dataset-group`` (scan-to-scan datasets: their groups),
    ``overall`` (dataset = bin = all), and ``overall-scan-to-map`` (only when the run mixes
    scan-to-scan and scan-to-map datasets).
    """
    s2s = set(scan_to_scan)
    parts = []
    sc = scenario_summary(p, paper or {})
    for name, g in sc.groupby("scenario", sort=True):
        parts.append(g.assign(grouping=f"scenario-{name}", bin="all" if name == "I" else g["sample"]))
    parts.append(summarize(p, ["dataset", "matcher"]).assign(grouping="dataset", bin="all"))
    truth = p[p["truth"]]
    s2m = truth[~truth["dataset"].isin(s2s)]
    for col in ("dist_bin", "angle_bin"):
        if len(s2m):
            t = summarize(s2m, ["dataset", col, "matcher"])
            parts.append(t.rename(columns={col: "bin"}).assign(grouping=f"dataset-{col}"))
    s2s_rows = p[p["dataset"].isin(s2s)]
    if len(s2s_rows):
        t = summarize(s2s_rows, ["dataset", "group", "matcher"])
        parts.append(t.rename(columns={"group": "bin"}).assign(grouping="dataset-group"))
    parts.append(summarize(p, ["matcher"]).assign(grouping="overall", dataset="all", bin="all"))
    if len(s2s_rows) and len(s2m):
        parts.append(summarize(s2m, ["matcher"]).assign(grouping="overall-scan-to-map", dataset="all", bin="all"))
    out = pd.concat([x.astype({"bin": object}) for x in parts if len(x)], ignore_index=True)
    return out[SUMMARY_KEYS + list(METRIC_COLUMNS)]
