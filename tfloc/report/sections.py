"""The markdown sections of ``report.md``: paper tables, per-dataset tables, failures.

Every function takes already-computed metric tables (:mod:`tfloc.evaluation.summary`) or
prepared rows (:func:`tfloc.evaluation.metrics.prepare`) and returns markdown text.
"""

from __future__ import annotations

import pandas as pd

from tfloc.evaluation.metrics import summarize
from tfloc.evaluation.outcome import OUTCOMES
from tfloc.evaluation.paper import PAPER_TF, TABLE_OF, paper_row

from .mdtable import num, pm, table

TITLES = {"I": "environmental detail (datasets detail-1/2/3)",
          "II": "initial angle offset (office-pool binned by angle_bin)",
          "III": "initial distance offset (office-pool binned by dist_bin)"}
UNIT = {"I": "", "II": "°", "III": " cm"}
PAPER_COLS = ["Mean Distance Error (cm)", "Mean Orientation Error (°)",
              "Distance Improvement (%)", "Orientation Improvement (%)"]


READING = """Reading these tables: a mean error is pulled up by a few diverged scans and a mean
improvement down (one scan can contribute −1000 % or less); the success rate, the medians
(next section, summary.csv: `dist_median_cm`, `dist_impr_median_pct`) and the outcome tables
show how typical scans fare. The paper reports means only.
"""


def _samples(sc: pd.DataFrame, scenario: str) -> list[str]:
    measured = list(dict.fromkeys(sc.loc[sc["scenario"] == scenario, "sample"]))
    paper = [r.key for r in PAPER_TF if r.scenario == scenario]
    return [k for k in paper if k in measured] + [k for k in measured if k not in paper]


def _label(scenario: str, key: str) -> str:
    r = paper_row(scenario, key)
    return f"{r.label} ({key}{UNIT[scenario]})" if r else f"— ({key}{UNIT[scenario]})"


def _measured(m: pd.Series) -> list[str]:
    return [num(m["dist_mean_cm"], 2), num(m["orient_mean_deg"], 3),
            num(m["dist_impr_mean_pct"], 2), num(m["orient_impr_mean_pct"], 2)]


def _n(m: pd.Series) -> str:
    ex = int(m["n_excluded"])
    return f"{int(m['n_truth'])}" + (f" ({ex} excl.)" if ex else "")


def _paper(scenario: str, key: str) -> list[str] | None:
    r = paper_row(scenario, key)
    if r is None:
        return None
    return [num(r.sample, 0), "paper (published)", f"{r.dist_err_cm:.4f}", f"{r.orient_err_deg:.4f}",
            f"{r.dist_impr_pct:.4f}", f"{r.orient_impr_pct:.4f}", "—"]


def paper_vs_tf(sc: pd.DataFrame, matcher: str = "tf") -> str:
    """Tables 2–4 as in the paper, the published row above the measured ``matcher`` row."""
    out = []
    for scenario in ("I", "II", "III"):
        samples = _samples(sc, scenario)
        if not samples:
            continue
        out.append(f"### Table {TABLE_OF[scenario]} — Scenario {scenario}: {TITLES[scenario]}\n")
        mine = sc[(sc["scenario"] == scenario) & (sc["matcher"] == matcher)].set_index("sample")
        if mine.empty:
            out.append(f"_Matcher `{matcher}` is not in this run: only the published values are shown._\n")
        rows = []
        for key in samples:
            p = _paper(scenario, key)
            if p:
                rows.append([_label(scenario, key), *p])
            if key in mine.index:
                m = mine.loc[key]
                rows.append([_label(scenario, key), _n(m), f"tfloc `{matcher}` (measured)", *_measured(m),
                             num(m["success_rate_pct"], 1)])
        out.append(table(["Scenario", "Sample", "Source", *PAPER_COLS, "Success (%)"], rows, "lrl" + "r" * 5))
    if out:
        out.append(READING)
    return "\n".join(out)


def all_matchers(sc: pd.DataFrame) -> str:
    """The same tables with every matcher of the run, grouped by sample (paper's tf row first)."""
    out = []
    for scenario in ("I", "II", "III"):
        samples = _samples(sc, scenario)
        if not samples:
            continue
        out.append(f"### Scenario {scenario} (Table {TABLE_OF[scenario]} layout): all matchers\n")
        rows = []
        s = sc[sc["scenario"] == scenario]
        for key in samples:
            r = paper_row(scenario, key)
            if r:
                rows.append([_label(scenario, key), num(r.sample, 0), "tf (paper, published)",
                             f"{r.dist_err_cm:.4f}", f"{r.orient_err_deg:.4f}", f"{r.dist_impr_pct:.4f}",
                             f"{r.orient_impr_pct:.4f}", "—", "—"])
            for _, m in s[s["sample"] == key].iterrows():
                rows.append([_label(scenario, key), _n(m), f"`{m['matcher']}`", *_measured(m),
                             num(m["dist_median_cm"], 2), num(m["success_rate_pct"], 1)])
        out.append(table(["Scenario", "Sample", "Matcher", *PAPER_COLS, "Median Distance Error (cm)",
                          "Success (%)"], rows, "lrl" + "r" * 6))
    return "\n".join(out)


def accuracy(g: pd.DataFrame) -> str:
    """Per matcher: n, success, distance/orientation error mean/median/p90/max, runtime."""
    rows = [[f"`{m['matcher']}`", _n(m), num(m["success_rate_pct"], 1),
             num(m["dist_mean_cm"], 2), num(m["dist_median_cm"], 2), num(m["dist_p90_cm"], 2),
             num(m["dist_max_cm"], 2), num(m["orient_mean_deg"], 3), num(m["orient_median_deg"], 3),
             num(m["orient_p90_deg"], 3), num(m["orient_max_deg"], 2),
             num(m["dist_impr_mean_pct"], 1), num(m["orient_impr_mean_pct"], 1),
             num(m["runtime_median_ms"], 1), num(m["runtime_p95_ms"], 1)] for _, m in g.iterrows()]
    return table(["Matcher", "n", "Success (%)", "Dist. mean (cm)", "median", "p90", "max",
                  "Orient. mean (°)", "median", "p90", "max", "Dist. impr. (%)", "Orient. impr. (%)",
                  "Runtime median (ms)", "p95 (ms)"], rows)


def success_by(p: pd.DataFrame, col: str, unit: str) -> str:
    """Success rate (%) per matcher (rows) and bin of ``col`` (columns), with n per cell."""
    t = summarize(p[p["truth"]], ["matcher", col])
    bins = [b for b in p[col].cat.categories if b in set(t[col])]
    rows = []
    for matcher, g in t.groupby("matcher", sort=True):
        cells = g.set_index(col)
        rows.append([f"`{matcher}`"] + [
            f"{num(cells.loc[b, 'success_rate_pct'], 1)} (n={int(cells.loc[b, 'n_truth'])})"
            if b in cells.index else "—" for b in bins])
    return table(["Matcher"] + [f"{b}{unit}" for b in bins], rows)


def outcomes(g: pd.DataFrame) -> str:
    """Outcome counts and shares per matcher."""
    extra = int(g["n_unscored"].sum()) > 0
    rows = []
    for _, m in g.iterrows():
        cells = [f"{int(m['n_' + o.replace('-', '_')])} ({num(m['share_' + o.replace('-', '_') + '_pct'], 1)} %)"
                 for o in OUTCOMES]
        rows.append([f"`{m['matcher']}`", int(m["n_truth"]), *cells] + ([int(m["n_unscored"])] if extra else []))
    return table(["Matcher", "n", *OUTCOMES] + (["unscored"] if extra else []), rows)


def scan_to_scan(g: pd.DataFrame) -> str:
    """Kümmerle-style table (translation in m, rotation in degrees) per matcher and group."""
    rows = []
    for _, m in g.iterrows():
        t_mean, t_std, t_max = (m[k] / 100.0 for k in ("dist_mean_cm", "dist_std_cm", "dist_max_cm"))
        rows.append([f"`{m['matcher']}`", m.get("group", "all"), _n(m), pm(t_mean, t_std, 3), num(t_max, 3),
                     pm(m["orient_mean_deg"], m["orient_std_deg"], 2), num(m["orient_max_deg"], 2),
                     num(m["success_rate_pct"], 1), num(m["runtime_median_ms"], 1),
                     num(m["runtime_p95_ms"], 1)])
    return table(["Matcher", "Relations", "n", "Trans. error (m) mean ± std", "max (m)",
                  "Rot. error (°) mean ± std", "max (°)", "Success (%)", "Runtime median (ms)",
                  "p95 (ms)"], rows, "llr" + "r" * 7)


def runtime_only(g: pd.DataFrame) -> str:
    """For datasets without truth: rows, status counts and runtimes per matcher."""
    rows = [[f"`{m['matcher']}`", int(m["n"]), int(m["n_timed"]), int(m["n_timeout"]), int(m["n_error"]),
             num(m["runtime_median_ms"], 1), num(m["runtime_p95_ms"], 1)] for _, m in g.iterrows()]
    return table(["Matcher", "n", "answered", "timeouts", "errors", "Runtime median (ms)", "p95 (ms)"], rows)


def failures(p: pd.DataFrame, limit: int = 5) -> str:
    """Timeouts and errors per matcher, with the most frequent error messages."""
    bad = p[~p["status"].isin(["ok", "failed"]) & ~p["status"].str.startswith("invalid:")]
    if bad.empty:
        return "No task timed out or raised an error.\n"
    out = []
    for matcher, g in bad.groupby("matcher", sort=True):
        msgs = g["status"].astype(str).str.slice(0, 160).value_counts().head(limit)
        out.append(f"- `{matcher}`: {len(g)} task(s) without an answer\n" +
                   "".join(f"  - {n} × `{s}`\n" for s, n in msgs.items()))
    return "".join(out)


def invalid(p: pd.DataFrame, limit: int = 5) -> str:
    """Tasks the data cannot pose (status ``invalid:``), per matcher, with their most frequent
    reasons (the ``file:line:`` of each is left out, so that equal reasons count together)."""
    bad = p[p["status"].str.startswith("invalid:")]
    out = []
    for matcher, g in bad.groupby("matcher", sort=True):
        why = g["status"].str.slice(len("invalid:")).str.replace(r"^\S*:\d+: ", "", regex=True)
        out.append(f"- `{matcher}`: {len(g)} task(s)\n" +
                   "".join(f"  - {n} × `{s[:160]}`\n" for s, n in why.value_counts().head(limit).items()))
    return "".join(out)
