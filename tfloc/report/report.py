"""``tfloc report RUN``: RUN/report.md, RUN/summary.csv and RUN/figures/*.png from a run's results.

Reads ``estimates.csv`` and ``run.json`` (:class:`tfloc.io.rundir.RunDir`), computes the metrics
(:mod:`tfloc.evaluation.metrics`, :mod:`tfloc.evaluation.summary`) and the paired tests
(:mod:`tfloc.evaluation.paired`, also written to ``paired.csv``), draws the figures
(:mod:`tfloc.report.figures`, :mod:`tfloc.report.failures`) and writes the markdown: the
header (:mod:`tfloc.report.provenance`), the definitions (:mod:`tfloc.report.definitions`), the
tables (:mod:`tfloc.report.sections`). A timing pass (``tfloc timing RUN``) is linked when present.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from tfloc.core.run import Run
from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.metrics import prepare, summarize
from tfloc.evaluation.paired import paired_table
from tfloc.evaluation.summary import (
    declaring,
    scenario_summary,
    summary_table,
    write_summary,
)
from tfloc.harness.workspace import load_dataset, map_of
from tfloc.io.estimates import status_kinds
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import GLOBAL, SCAN_TO_SCAN, SEQUENCE

from . import figures as F
from . import sections as S
from .definitions import definitions
from .failures import draw_failures, failures_section
from .figures import MANY_MATCHERS
from .headline import headline_section
from .landscape import draw_landscapes, landscape_section
from .provenance import header
from .truthfree import load_truth_free, truth_free_section


@dataclass(frozen=True)
class ReportFiles:
    """What :func:`write_report` wrote."""

    report: Path
    summary: Path
    figures: tuple[Path, ...]



def load_run(run_dir: Path) -> tuple[pd.DataFrame, Run]:
    """The rows and the ``run.json`` of a run directory (:class:`~tfloc.io.rundir.RunDir`;
    ``run.json`` may be missing: provenance unknown, default thresholds)."""
    rd = RunDir(run_dir)
    rd.require_results()
    return rd.results(), rd.info()


def _dataset_section(p: pd.DataFrame, name: str, s2s: set[str]) -> str:
    g = p[p["dataset"] == name]
    out = [f"### {name}\n"]
    if not g["truth"].any():
        out.append("_No ground truth in this dataset: accuracy, success and outcome tables are skipped._\n")
        out.append(S.runtime_only(summarize(g, ["matcher"])))
        return "\n".join(out)
    t = g[g["truth"]]
    if name in s2s:
        out.append("Scan-to-scan (Kümmerle et al. 2009 style): errors of the estimated relative pose.\n")
        k = pd.concat([summarize(t, ["matcher"]).assign(group="all"), summarize(t, ["matcher", "group"])])
        out.append(S.scan_to_scan(k.sort_values(["matcher", "group"], key=lambda s: s.replace("all", ""))))
        out.append("Outcomes (count and share of scans with ground truth):\n")
        out.append(S.outcomes(summarize(t, ["matcher"])))
    else:
        out += _scan_to_map_tables(t)
    return "\n".join(out)


def _scan_to_map_tables(t: pd.DataFrame) -> list[str]:
    """Accuracy, outcomes and success by offset bin of scored scan-to-map rows."""
    per_matcher = summarize(t, ["matcher"])
    return [S.accuracy(per_matcher), "Outcomes (count and share of scans with ground truth):\n",
            S.outcomes(per_matcher), "Success rate (%) [95 % CI] by initial distance offset:\n",
            S.success_by(t, "dist_bin", " cm"), "Success rate (%) [95 % CI] by initial angle offset:\n",
            S.success_by(t, "angle_bin", "°")]


def _paired_section(pt: pd.DataFrame, sweep: bool) -> list[str]:
    out = ["## Paired comparisons (same scans)\n",
           ("Success of every label against the run's first, " if sweep else
            "Success of every pair of matchers ") + "scan by scan (see Definitions; `paired.csv` has "
           "every row). Difference = a − b in percentage points.\n"]
    for d, g in pt.groupby("dataset", sort=False):
        out.append(f"### {'scan-to-map datasets pooled' if d == 'all' else d}\n")
        out.append(S.paired(g))
    return out


def render(run_dir: Path, run: dict, p: pd.DataFrame, thr: Thresholds, s2s: set[str],
           figs: list[Path], pt: pd.DataFrame | None = None, failures: str = "", landscape: str = "",
           line_labels: list[str] | None = None, sweep: bool = False, paper: dict | None = None,
           headline: str = "") -> str:
    """The whole report.md text (``sweep``: a parameter sweep, see :data:`MANY_MATCHERS`;
    ``line_labels``: the labels its line figures show; ``paper``: dataset → the paper scenarios
    it declares; ``headline``: the opening section, :mod:`tfloc.report.headline`)."""
    paper = paper or {}
    parts = [header(run_dir, run, p, thr, s2s), headline, definitions(thr, paper)]
    truth = p[p["truth"]]
    sc = scenario_summary(truth, paper)
    if not truth.empty and len(sc):
        parts.append("## The paper's Tables 2–4: published tf against tfloc's tf\n")
        parts.append(S.paper_vs_tf(sc))
        parts.append("## Tables 2–4 for every matcher\n")
        parts.append(S.all_matchers(sc))
    elif truth.empty:
        parts.append("## Scoring\n\n_No scan in this run has ground truth: accuracy, success and outcome "
                     "sections are skipped; only runtimes are reported._\n")
    else:
        parts.append("_No dataset of this run declares one of the paper's scenarios (`paper_scenarios` "
                     "in its `scenario.json`): the paper's tables are not shown._\n")
    parts.append("## Results per dataset\n")
    parts += [_dataset_section(p, d, s2s) for d in p["dataset"].unique()]
    s2m = truth[~truth["dataset"].isin(s2s)]
    if s2m["dataset"].nunique() > 1:
        names = ", ".join(s2m["dataset"].unique())
        parts.append(f"## Scan-to-map datasets pooled ({names})\n")
        if s2s:
            parts.append("Scan-to-scan datasets are left out: their initial offsets are odometry, often "
                         "under a millimetre, which makes the improvement meaningless.\n")
        parts += _scan_to_map_tables(s2m)
    if pt is not None and len(pt):
        parts += _paired_section(pt, sweep)
    if (run_dir / "timing.md").is_file():
        parts.append("## Quiet re-timing\n\nA side-by-side timing pass of a stratified sample of this "
                     "run's scans in one pinned process: [timing.md](timing.md).\n")
    if landscape:
        parts.append(landscape)
    parts.append("## Tasks without an answer (timeouts, errors)\n")
    parts.append(S.failures(p))
    if (status_kinds(p["status"]) == "invalid").any():
        parts.append("## Tasks the data cannot pose (invalid)\n")
        parts.append("The scan's problem cannot be posed (e.g. its initial pose lies outside the map): no "
                     "matcher ran. These count as no-answer in the success rate, not as errors.\n")
        parts.append(S.invalid(p))
    if failures:
        parts.append("## Failure pictures\n")
        parts.append(failures)
    if figs:
        parts.append("## Figures\n")
        if line_labels:
            shown = ", ".join(f"`{m}`" for m in line_labels)
            parts.append(f"A parameter sweep: the line figures (scenario errors, basin, error CDF) "
                         f"show the first label and the seven most successful others ({shown}); "
                         "the runtime and outcome figures show every label.\n")
        parts += [f"![{f.stem}](figures/{f.name})\n" for f in figs]
    return "\n".join(parts)


def label_order(run: dict, p: pd.DataFrame) -> list[str]:
    """The run's matcher labels in the order of its configuration (sorted without run.json)."""
    order = [m.get("label", m.get("name")) for m in run.get("config", {}).get("matchers", [])]
    return [m for m in order if m in set(p["matcher"])] or sorted(p["matcher"].unique())


def line_figure_matchers(p: pd.DataFrame, order: list[str], most: int = 8) -> list[str]:
    """The labels a sweep's line figures show (a line per label is unreadable beyond a dozen):
    the run's first label and the ``most`` − 1 others with the highest success rate."""
    t = p[p["truth"] & p["matcher"].isin(order[1:])]
    rate = (t["outcome_eval"] == "success").groupby(t["matcher"]).mean()
    best = sorted(rate.index, key=lambda m: (-rate[m], order.index(m)))[:most - 1]
    return [order[0], *best]


def _maps(info: Run, names: set[str]) -> dict:
    """The maps of the run's datasets ``names``, from the workspace (read once per process)."""
    out = {}
    for n, d in info.paths.items():
        scenario, scans = load_dataset(str(d)) if n in names else (None, {})
        if scans:
            out[n] = map_of(scenario, next(iter(scans.values())))
    return out


def _tracking(run_dir: Path, df: pd.DataFrame, info: Run, thr: Thresholds, with_figures: bool) -> str:
    """The tracking section of a run's sequence datasets (:mod:`tfloc.report.tracking`); their
    scores per (sequence, matcher) go to ``tracking.csv``."""
    from .tracking import sequence_scores, tracking_section

    scenarios = {n: load_dataset(str(d))[0] for n, d in info.paths.items() if n in set(df["dataset"])}
    maps = _maps(info, set(df["dataset"])) if with_figures else {}
    sequence_scores(df, scenarios, thr).drop(columns="cpu_ms_all").to_csv(
        run_dir / "tracking.csv", index=False, float_format="%.6g")
    return tracking_section(df, scenarios, maps, run_dir, thr, figures=with_figures)


def _relocalization(run_dir: Path, df: pd.DataFrame, info: Run, thr: Thresholds) -> str:
    """The global section of a run's global datasets (:mod:`tfloc.report.relocalization`)."""
    from .relocalization import relocalization_section

    maps = _maps(info, set(df["dataset"]))
    return relocalization_section(df, maps, run_dir, thr)


def write_report(run_dir: str | Path, thresholds: Thresholds | None = None,
                 with_figures: bool = True) -> ReportFiles:
    """Write report.md, summary.csv and figures/*.png into ``run_dir``; returns their paths.
    Sequence datasets get the tracking section; the other sections cover the other datasets."""
    run_dir = Path(run_dir)
    df, info = load_run(run_dir)
    run = info.doc
    thr = thresholds or info.thresholds
    names = list(df["dataset"].unique())
    seq, glob = info.datasets_in(names, SEQUENCE), info.datasets_in(names, GLOBAL)
    prepared = prepare(df, thr)
    tf = load_truth_free(run_dir, prepared, sorted(seq), thr)
    top = headline_section(prepared, {n: info.mode(n) for n in names}, thr, run_dir, tf)
    tracking = _tracking(run_dir, df[df["dataset"].isin(seq)], info, thr, with_figures) if seq else ""
    if seq:
        blind = sorted(n for n in seq if not prepared.loc[prepared["dataset"] == n, "truth"].any())
        tracking += "\n" + truth_free_section(tf, blind)
    if glob:
        tracking = _relocalization(run_dir, df[df["dataset"].isin(glob)], info, thr) + "\n" + tracking
    if df["dataset"].isin(seq | glob).all():
        p = prepared
        report = run_dir / "report.md"
        report.write_text("\n".join([header(run_dir, run, p, thr, set()), top, tracking]))
        return ReportFiles(report, run_dir / ("tracking.csv" if seq else "relocalization.csv"), ())
    p = prepare(df[~df["dataset"].isin(seq | glob)], thr)
    s2s = info.datasets_in(list(p["dataset"].unique()), SCAN_TO_SCAN)
    paper = {d: s for d, s in info.paper_scenarios().items() if d in set(p["dataset"])}
    summary = write_summary(summary_table(p, s2s, paper), run_dir / "summary.csv")
    order = label_order(run, p)
    sweep = len(order) > MANY_MATCHERS  # a parameter sweep: compare each label with the first only
    pt = paired_table(p, s2s, reference=order[0] if sweep else None)
    pt.to_csv(run_dir / "paired.csv", index=False, float_format="%.6g")
    figs: list[Path] = []
    failures = landscape = ""
    line_labels = line_figure_matchers(p, order) if sweep and with_figures else None
    if with_figures:
        fd = run_dir / "figures"
        lines = p[p["matcher"].isin(line_labels)] if line_labels else p
        sc = scenario_summary(lines[lines["truth"]], paper)
        made = [F.fig_scenarios(sc, fd / "scenario_errors.png") if len(sc) else None,
                F.fig_basin(lines, fd / "basin.png", s2s, paper), F.fig_cdf(lines, fd / "error_cdf.png", thr),
                F.fig_runtime(p, fd / "runtime.png"), F.fig_outcomes(p, fd / "outcomes.png", s2s)]
        figs = [f for f in made if f is not None]
        drawn = p[p["matcher"] == order[0]] if sweep else p
        failures = failures_section(draw_failures(run_dir, drawn, info.paths))
        binned = sorted(set(declaring(paper, "II")) | set(declaring(paper, "III")))
        landscape = landscape_section(*draw_landscapes(run_dir, p, info.paths, binned))
    report = run_dir / "report.md"
    text = render(run_dir, run, p, thr, s2s, figs, pt, failures, landscape, line_labels, sweep, paper, top)
    report.write_text(text + ("\n" + tracking if tracking else ""))
    return ReportFiles(report, summary, tuple(figs))
