"""``report.md`` + ``summary.csv`` + figures for a run directory (tables laid out like the paper's 2–4)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import DatasetError
from . import figures
from .metrics import OUTCOMES, summary_table, with_errors
from .runner import COLUMNS

# The paper's published values: (mean dist error cm, mean orient error deg, dist impr. %, orient impr. %).
PAPER = {
    "I": {"detail-1": (7.7878, 1.0526, 94.8979, 82.8125), "detail-2": (7.9858, 0.6315, 64.3136, 90.6250),
          "detail-3": (9.3984, 0.8421, 93.0935, 88.2353)},
    "II": {"1": (8.5752, 0.4368, 94.2968, 77.4194), "2": (6.5290, 0.7371, 95.3235, 86.2746),
           "3": (10.0688, 1.0536, 92.7747, 90.5661)},
    "III": {"1": (6.0639, 0.4210, 89.8533, 93.7500), "2": (8.6486, 1.0538, 93.9186, 84.6154),
            "3": (10.4595, 1.0526, 95.5024, 85.5073)},
}
TITLES = {"I": ("Table 2 — Scenario I: environmental detail", "detail level"),
          "II": ("Table 3 — Scenario II: initial angle offset (0–5°, 5–10°, 10–15°)", "angle class"),
          "III": ("Table 4 — Scenario III: initial distance offset (0–100, 100–200, 200–300 cm)", "distance class")}
PAPER_MATCHER = "tf"


def read_estimates(path: Path) -> pd.DataFrame:
    """Read ``estimates.csv`` strictly (header must match)."""
    if not path.is_file():
        raise DatasetError(f"{path}: no estimates.csv (run 'tfloc bench' first)")
    df = pd.read_csv(path, dtype={"scan_id": str, "group": str, "dataset": str, "matcher": str,
                                  "status": str, "outcome": str}, keep_default_na=False,
                     na_values={c: [""] for c in COLUMNS if c not in ("dataset", "scan_id", "group", "matcher", "status", "outcome")})
    if list(df.columns) != COLUMNS:
        raise DatasetError(f"{path}:1: unexpected columns {list(df.columns)}")
    return df


def _f(v, nd: int = 2) -> str:
    return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{nd}f}"


def _paper_table(summary: pd.DataFrame, sc: str) -> list[str]:
    title, cls = TITLES[sc]
    s = summary[(summary["matcher"] == PAPER_MATCHER) & (summary["scenario"] == sc)]
    lines = [f"### {title}", "",
             f"`{PAPER_MATCHER}` measured here vs. the paper's published values (paper in parentheses).", "",
             f"| {cls} | samples | mean distance error (cm) | mean orientation error (°) | distance improvement (%) | orientation improvement (%) | success rate |",
             "|---|---|---|---|---|---|---|"]
    for group, paper in PAPER[sc].items():
        r = s[s["group"] == group]
        if r.empty:
            lines.append(f"| {group} | 0 | – ({paper[0]}) | – ({paper[1]}) | – ({paper[2]}) | – ({paper[3]}) | – |")
            continue
        r = r.iloc[0]
        lines.append(f"| {group} | {r['n']} | {_f(r['mean_dist_cm'])} ({paper[0]}) | {_f(r['mean_orient_deg'])} ({paper[1]}) "
                     f"| {_f(r['dist_improvement_pct'], 1)} ({paper[2]}) | {_f(r['orient_improvement_pct'], 1)} ({paper[3]}) "
                     f"| {_f(r['success_rate'], 3)} |")
    return lines + [""]


def _matcher_table(summary: pd.DataFrame, sc: str) -> list[str]:
    s = summary[summary["scenario"] == sc]
    if s.empty:
        return []
    title = TITLES[sc][0].split("—", 1)[1].strip() if sc in TITLES else sc
    lines = [f"#### All matchers — {title}", "",
             "| matcher | group | n | mean dist (cm) | mean orient (°) | dist impr. (%) | orient impr. (%) | success | local-opt. | ambiguous | no-answer |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in s.iterrows():
        lines.append(f"| {r['matcher']} | {r['group']} | {r['n']} | {_f(r['mean_dist_cm'])} | {_f(r['mean_orient_deg'])} "
                     f"| {_f(r['dist_improvement_pct'], 1)} | {_f(r['orient_improvement_pct'], 1)} | {_f(r['success_rate'], 3)} "
                     f"| {r['n_local-optimum']} | {r['n_ambiguous']} | {r['n_no-answer']} |")
    return lines + [""]


def _overall_table(summary: pd.DataFrame) -> list[str]:
    s = summary[summary["scenario"] == "all"]
    lines = ["| matcher | n | answered | success | mean / median / p90 / max dist (cm) | mean / median / p90 / max orient (°) "
             "| dist impr. (%) | orient impr. (%) | runtime median / p95 (ms) |", "|---|---|---|---|---|---|---|---|---|"]
    for _, r in s.iterrows():
        d = " / ".join(_f(r[f"{k}_dist_cm"]) for k in ("mean", "median", "p90", "max"))
        o = " / ".join(_f(r[f"{k}_orient_deg"]) for k in ("mean", "median", "p90", "max"))
        lines.append(f"| {r['matcher']} | {r['n']} | {r['n_answered']} | {_f(r['success_rate'], 3)} | {d} | {o} "
                     f"| {_f(r['dist_improvement_pct'], 1)} | {_f(r['orient_improvement_pct'], 1)} "
                     f"| {_f(r['runtime_median_ms'], 1)} / {_f(r['runtime_p95_ms'], 1)} |")
    return lines + [""]


def _outcome_table(df: pd.DataFrame) -> list[str]:
    tab = pd.crosstab(df["matcher"], df["outcome"]).reindex(columns=list(OUTCOMES), fill_value=0)
    lines = ["| matcher | " + " | ".join(OUTCOMES) + " |", "|---" * (len(OUTCOMES) + 1) + "|"]
    lines += [f"| {m} | " + " | ".join(str(int(v)) for v in row) + " |" for m, row in tab.iterrows()]
    errs = df[df["status"].astype(str).str.startswith("error:")]
    if len(errs):
        lines += ["", "Most frequent errors:", ""]
        for (m, st), n in errs.groupby(["matcher", "status"]).size().sort_values(ascending=False).head(10).items():
            lines.append(f"- `{m}` × {n}: `{st}`")
    return lines + [""]


def write_report(run_dir: str | Path) -> Path:
    """Write ``summary.csv``, ``figures/*.png`` and ``report.md`` into ``run_dir``."""
    run_dir = Path(run_dir)
    df = read_estimates(run_dir / "estimates.csv")
    df = df[np.isfinite(df[["true_x", "true_y", "true_theta"]].to_numpy(float)).all(axis=1)]
    if df.empty:
        raise DatasetError(f"{run_dir}/estimates.csv: no scored rows (no true poses)")
    df = with_errors(df)
    info = json.loads((run_dir / "run.json").read_text()) if (run_dir / "run.json").exists() else {}
    cfg = info.get("config", {})
    summary = summary_table(df)
    summary.to_csv(run_dir / "summary.csv", index=False, float_format="%.6g")
    fig_dir = run_dir / "figures"
    fig_dir.mkdir(exist_ok=True)
    figures.scenario_errors(summary, fig_dir / "scenario_errors.png")
    figures.convergence_basin(df, fig_dir / "convergence_basin.png")
    figures.error_cdf(df, fig_dir / "error_cdf.png")
    figures.runtime(df, fig_dir / "runtime.png")
    figures.outcomes(df, fig_dir / "outcomes.png")
    lines = [f"# Benchmark report: {cfg.get('name', run_dir.name)}", "",
             f"- Matchers: {', '.join(sorted(df['matcher'].unique()))}; datasets: {', '.join(sorted(df['dataset'].unique()))}; "
             f"{len(df)} (scan, matcher) rows.",
             f"- Commit: `{info.get('git_commit')}`; machine: {info.get('machine', {}).get('platform')}, "
             f"{info.get('machine', {}).get('cpu_count')} CPUs; {cfg.get('jobs')} worker(s), "
             f"{info.get('threads_per_worker')} thread(s) each; time limit {cfg.get('timeout_s')} s per scan.",
             "", "## Definitions", "",
             "- Distance error ‖(x̂, ŷ) − (x, y)‖ in cm; orientation error |angdiff(θ̂, θ)| in degrees (Eq. 6).",
             "- **Improvement** (the paper's): 100·(1 − error/initial error), computed per scan and averaged "
             "over the scans with an answer (scans with a zero initial error are left out).",
             f"- **Success**: distance error ≤ {100 * cfg.get('success_dist_m', 0.10):g} cm and orientation error "
             f"≤ {cfg.get('success_orient_deg', 2.0):g}°.",
             "- **Outcome** of a failed scan, from the matcher's own `score` (lower is better): `local-optimum` if the "
             "score at the true pose is lower than at the answer (the search stopped short); `ambiguous` if not "
             "(its objective prefers the wrong pose); `no-answer` if it raised, timed out or returned no finite pose; "
             "`unscored` if `score` failed.",
             "- Error statistics use the answered scans only; runtime is the wall time of `localize` alone.",
             "- Scenario I = datasets detail-1/2/3; Scenarios II and III = the office-pool scans binned by their "
             "initial angle offset and initial distance offset, computed from the true and initial poses.",
             "", "## The paper's tables", ""]
    for sc in ("I", "II", "III"):
        lines += _paper_table(summary, sc) + _matcher_table(summary, sc)
    lines += ["## Overall per matcher", ""] + _overall_table(summary)
    lines += ["## Failure outcomes", ""] + _outcome_table(df)
    lines += ["## Figures", ""] + [f"![{n}](figures/{n}.png)" for n in
                                   ("scenario_errors", "convergence_basin", "error_cdf", "runtime", "outcomes")]
    lines += ["", "All metrics per matcher × scenario × group: `summary.csv`.", ""]
    path = run_dir / "report.md"
    path.write_text("\n".join(lines))
    return path
