"""The markdown sections of ``report.md``: paper tables, per-dataset tables, failures.

Every function takes already-computed metric tables (:mod:`tfloc.evaluation.summary`) or
prepared rows (:func:`tfloc.evaluation.metrics.prepare`) and returns markdown text.
"""

from __future__ import annotations

import pandas as pd

from tfloc.evaluation.metrics import status_kinds, summarize
from tfloc.evaluation.outcome import OUTCOMES
from tfloc.evaluation.paired import ALPHA
from tfloc.evaluation.paper import PAPER_TF, TABLE_OF, paper_row

from .mdtable import num, pm, table

TITLES = {"I": "environmental detail (one sample per dataset)",
          "II": "initial angle offset (binned by angle_bin)",
          "III": "initial distance offset (binned by dist_bin)"}


def _title(sc: pd.DataFrame, scenario: str) -> str:
    """The scenario's title and the datasets its rows come from."""
    names = sorted({n for d in sc.loc[sc["scenario"] == scenario, "dataset"] for n in str(d).split("+")})
    return f"{TITLES[scenario]}; datasets: {', '.join(names)}"
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


def _scenarios(sc: pd.DataFrame) -> list[tuple[str, list[str]]]:
    """The paper's scenarios present in ``sc`` with their samples, in table order."""
    return [(s, _samples(sc, s)) for s in ("I", "II", "III") if _samples(sc, s)]


def _label(scenario: str, key: str) -> str:
    r = paper_row(scenario, key)
    return f"{r.label} ({key}{UNIT[scenario]})" if r else f"— ({key}{UNIT[scenario]})"


def _measured(m: pd.Series) -> list[str]:
    return [num(m["dist_mean_cm"], 2), num(m["orient_mean_deg"], 3),
            num(m["dist_impr_mean_pct"], 2), num(m["orient_impr_mean_pct"], 2)]


def ci(m: pd.Series, value: str, lo: str, hi: str, digits: int = 1) -> str:
    """``value [lo–hi]`` of metric row ``m`` (the interval omitted when missing)."""
    a, b = num(m[lo], digits), num(m[hi], digits)
    return num(m[value], digits) + ("" if "—" in (a, b) else f" [{a}–{b}]")


def _success(m: pd.Series) -> str:
    return ci(m, "success_rate_pct", "success_lo_pct", "success_hi_pct")


def _published(r) -> list[str]:
    """The paper's four published values of one row, as printed in its tables."""
    return [f"{r.dist_err_cm:.4f}", f"{r.orient_err_deg:.4f}", f"{r.dist_impr_pct:.4f}", f"{r.orient_impr_pct:.4f}"]


def _n(m: pd.Series) -> str:
    ex = int(m["n_excluded"])
    return f"{int(m['n_truth'])}" + (f" ({ex} excl.)" if ex else "")


def _paper(scenario: str, key: str) -> list[str] | None:
    r = paper_row(scenario, key)
    if r is None:
        return None
    return [num(r.sample, 0), "paper (published)", *_published(r), "—"]


def paper_vs_tf(sc: pd.DataFrame, matcher: str = "tf") -> str:
    """Tables 2–4 as in the paper, the published row above the measured ``matcher`` row."""
    out = []
    for scenario, samples in _scenarios(sc):
        out.append(f"### Table {TABLE_OF[scenario]} — Scenario {scenario}: {_title(sc, scenario)}\n")
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
                             _success(m)])
        out.append(table(["Scenario", "Sample", "Source", *PAPER_COLS, "Success (%) [95 % CI]"], rows,
                         "lrl" + "r" * 5))
    if out:
        out.append(READING)
    return "\n".join(out)


def all_matchers(sc: pd.DataFrame) -> str:
    """The same tables with every matcher of the run, grouped by sample (paper's tf row first)."""
    out = []
    for scenario, samples in _scenarios(sc):
        out.append(f"### Scenario {scenario} (Table {TABLE_OF[scenario]} layout): all matchers\n")
        rows = []
        s = sc[sc["scenario"] == scenario]
        for key in samples:
            r = paper_row(scenario, key)
            if r:
                rows.append([_label(scenario, key), num(r.sample, 0), "tf (paper, published)",
                             *_published(r), "—", "—"])
            for _, m in s[s["sample"] == key].iterrows():
                rows.append([_label(scenario, key), _n(m), f"`{m['matcher']}`", *_measured(m),
                             num(m["dist_median_cm"], 2), _success(m)])
        out.append(table(["Scenario", "Sample", "Matcher", *PAPER_COLS, "Median Distance Error (cm)",
                          "Success (%) [95 % CI]"], rows, "lrl" + "r" * 6))
    return "\n".join(out)


def _cpu(m: pd.Series) -> list[str]:
    """CPU median [95 % CI], CPU p95 and wall median, ms."""
    return [ci(m, "cpu_median_ms", "cpu_median_lo_ms", "cpu_median_hi_ms"), num(m["cpu_p95_ms"], 1),
            num(m["runtime_median_ms"], 1)]


CPU_COLS = ["CPU median (ms) [95 % CI]", "CPU p95 (ms)", "wall median (ms)"]


def accuracy(g: pd.DataFrame) -> str:
    """Per matcher: n, success, distance/orientation error mean/median/p90/max, CPU time."""
    rows = [[f"`{m['matcher']}`", _n(m), _success(m),
             num(m["dist_mean_cm"], 2), ci(m, "dist_median_cm", "dist_median_lo_cm", "dist_median_hi_cm", 2),
             num(m["dist_p90_cm"], 2),
             num(m["dist_max_cm"], 2), num(m["orient_mean_deg"], 3), num(m["orient_median_deg"], 3),
             num(m["orient_p90_deg"], 3), num(m["orient_max_deg"], 2),
             num(m["dist_impr_mean_pct"], 1), num(m["orient_impr_mean_pct"], 1), *_cpu(m)]
            for _, m in g.iterrows()]
    return table(["Matcher", "n", "Success (%) [95 % CI]", "Dist. mean (cm)", "median [95 % CI]", "p90", "max",
                  "Orient. mean (°)", "median", "p90", "max", "Dist. impr. (%)", "Orient. impr. (%)",
                  *CPU_COLS], rows)


def success_by(p: pd.DataFrame, col: str, unit: str) -> str:
    """Success rate (%) per matcher (rows) and bin of ``col`` (columns), with n per cell."""
    t = summarize(p[p["truth"]], ["matcher", col])
    bins = [b for b in p[col].cat.categories if b in set(t[col])]
    rows = []
    for matcher, g in t.groupby("matcher", sort=True):
        cells = g.set_index(col)
        rows.append([f"`{matcher}`"] + [
            f"{_success(cells.loc[b])} (n={int(cells.loc[b, 'n_truth'])})" if b in cells.index else "—"
            for b in bins])
    return table(["Matcher"] + [f"{b}{unit}" for b in bins], rows)


def outcomes(g: pd.DataFrame) -> str:
    """Outcome counts and shares per matcher, and where failed searches ended: near the truth
    (≤ 30 cm, ≤ 5°: a stall in the basin) or farther from it than they started (diverged)."""
    extra = int(g["n_unscored"].sum()) > 0
    rows = []
    for _, m in g.iterrows():
        cells = [f"{int(m['n_' + o.replace('-', '_')])} ({num(m['share_' + o.replace('-', '_') + '_pct'], 1)} %)"
                 for o in OUTCOMES]
        rows.append([f"`{m['matcher']}`", int(m["n_truth"]), *cells] + ([int(m["n_unscored"])] if extra else [])
                    + [int(m["n_near"]), int(m["n_diverged"])])
    return table(["Matcher", "n", *OUTCOMES] + (["unscored"] if extra else [])
                 + ["failed near the truth", "diverged"], rows)


def scan_to_scan(g: pd.DataFrame) -> str:
    """Kümmerle-style table (translation in m, rotation in degrees) per matcher and group."""
    rows = []
    for _, m in g.iterrows():
        t_mean, t_std, t_max = (m[k] / 100.0 for k in ("dist_mean_cm", "dist_std_cm", "dist_max_cm"))
        rows.append([f"`{m['matcher']}`", m.get("group", "all"), _n(m), pm(t_mean, t_std, 3), num(t_max, 3),
                     pm(m["orient_mean_deg"], m["orient_std_deg"], 2), num(m["orient_max_deg"], 2),
                     _success(m), *_cpu(m)])
    return table(["Matcher", "Relations", "n", "Trans. error (m) mean ± std", "max (m)",
                  "Rot. error (°) mean ± std", "max (°)", "Success (%) [95 % CI]", *CPU_COLS],
                 rows, "llr" + "r" * 8)


def runtime_only(g: pd.DataFrame) -> str:
    """For datasets without truth: rows, status counts and runtimes per matcher."""
    rows = [[f"`{m['matcher']}`", int(m["n"]), int(m["n_timed"]), int(m["n_timeout"]), int(m["n_error"]),
             *_cpu(m)] for _, m in g.iterrows()]
    return table(["Matcher", "n", "answered", "timeouts", "errors", *CPU_COLS], rows)


def failures(p: pd.DataFrame, limit: int = 5) -> str:
    """Timeouts and errors per matcher, with the most frequent error messages."""
    bad = p[status_kinds(p["status"]).isin(["timeout", "error"])]
    if bad.empty:
        return "No task timed out or raised an error.\n"
    out = []
    for matcher, g in bad.groupby("matcher", sort=True):
        msgs = g["status"].astype(str).str.slice(0, 160).value_counts().head(limit)
        out.append(f"- `{matcher}`: {len(g)} task(s) without an answer\n" +
                   "".join(f"  - {n} × `{s}`\n" for s, n in msgs.items()))
    return "".join(out)


def paired(t: pd.DataFrame) -> str:
    """Paired comparisons of one family (:func:`tfloc.evaluation.paired.paired_comparisons`)."""
    if t.empty:
        return "_Fewer than two matchers with common scans._\n"
    rows = [[f"`{r.a}` − `{r.b}`", int(r.n), num(r.success_a_pct, 1), num(r.success_b_pct, 1),
             f"{int(r.only_a)} / {int(r.only_b)}",
             f"{num(r.diff_pct, 1)} [{num(r.diff_lo_pct, 1)}, {num(r.diff_hi_pct, 1)}]",
             _p(r.p_mcnemar), _p(r.p_holm), "**yes**" if r.significant else "no"] for r in t.itertuples()]
    return table(["Pair (a − b)", "scans", "a (%)", "b (%)", "only a / only b succeeded",
                  "difference (pp) [95 % CI]", "McNemar p", "Holm p", f"significant (α = {ALPHA:g})"], rows)


def _p(p: float) -> str:
    return "<1e-4" if p < 1e-4 else f"{p:.4f}"


def invalid(p: pd.DataFrame, limit: int = 5) -> str:
    """Tasks the data cannot pose (status ``invalid:``), per matcher, with their most frequent
    reasons (the ``file:line:`` of each is left out, so that equal reasons count together)."""
    bad = p[status_kinds(p["status"]) == "invalid"]
    out = []
    for matcher, g in bad.groupby("matcher", sort=True):
        why = g["status"].str.slice(len("invalid:")).str.replace(r"^\S*:\d+: ", "", regex=True)
        out.append(f"- `{matcher}`: {len(g)} task(s)\n" +
                   "".join(f"  - {n} × `{s[:160]}`\n" for s, n in why.value_counts().head(limit).items()))
    return "".join(out)
