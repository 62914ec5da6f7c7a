"""``tfloc report RUN``'s drawing: RUN/report.md and RUN/figures/*.png from a run's rows and the
tables derived from them.

The tables (``headline.csv``, ``summary.csv``, ``paired.csv``, the tracking and global tables,
the truth-free verdict's) are made by the derive step (:mod:`tfloc.harness.derive`) and read
here through the store (:class:`tfloc.io.rundir.RunDir`); this module writes no table. It draws
the figures (:mod:`tfloc.report.figures`, :mod:`tfloc.report.failures`, the landscapes
:mod:`tfloc.harness.landscape` computed) and writes the markdown: the header
(:mod:`tfloc.report.provenance`), the headline (:mod:`tfloc.report.headline`), the definitions
(:mod:`tfloc.report.definitions`), the tables (:mod:`tfloc.report.sections`). A timing pass
(``tfloc timing RUN``) is linked when present.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from tfloc.core.rows.headline import HeadlineRow
from tfloc.core.run import RunRecord
from tfloc.core.thresholds import Thresholds
from tfloc.errors import TflocError
from tfloc.evaluation.metrics import prepare, status_kinds, summarize
from tfloc.evaluation.paired import MANY_MATCHERS
from tfloc.evaluation.summary import scenario_summary
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import GLOBAL, SCAN_TO_SCAN, SEQUENCE, load_dataset, map_for
from tfloc.io.tables import HEADLINE, PAIRED
from tfloc.paper.landscape import LandscapePanel

from . import figures as F
from . import sections as S
from .definitions import definitions
from .failures import draw_failures, failures_section
from .headline import headline_section
from .landscape import draw_landscapes, landscape_section
from .provenance import header
from .truthfree import load_truth_free, truth_free_section


@dataclass(frozen=True)
class ReportFiles:
    """What :func:`write_report` wrote."""

    report: Path
    figures: tuple[Path, ...]


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


def render(run_dir: Path, run: RunRecord, p: pd.DataFrame, thr: Thresholds, s2s: set[str],
           figs: list[Path], pt: pd.DataFrame | None = None, failures: str = "", landscape: str = "",
           line_labels: list[str] | None = None, sweep: bool = False, paper: dict | None = None,
           headline: str = "", stale_code: list[str] | None = None) -> str:
    """The whole report.md text (``sweep``: a parameter sweep, see :data:`MANY_MATCHERS`;
    ``line_labels``: the labels its line figures show; ``paper``: dataset → the paper scenarios
    it declares; ``headline``: the opening section, :mod:`tfloc.report.headline`; ``stale_code``:
    the labels whose rows this checkout's code would not make)."""
    paper = paper or {}
    parts = [header(run_dir, run, p, thr, s2s, stale_code), headline, definitions(thr, paper)]
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
    if RunDir(run_dir).timing_md.is_file():
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


def label_order(run: RunRecord, p: pd.DataFrame) -> list[str]:
    """The run's matcher labels in the order of its configuration (sorted without run.json)."""
    return [m for m in run.labels if m in set(p["matcher"])] or sorted(p["matcher"].unique())


def line_figure_matchers(p: pd.DataFrame, order: list[str], most: int = 8) -> list[str]:
    """The labels a sweep's line figures show (a line per label is unreadable beyond a dozen):
    the run's first label and the ``most`` − 1 others with the highest success rate."""
    t = p[p["truth"] & p["matcher"].isin(order[1:])]
    rate = (t["outcome_eval"] == "success").groupby(t["matcher"]).mean()
    best = sorted(rate.index, key=lambda m: (-rate[m], order.index(m)))[:most - 1]
    return [order[0], *best]


def _loaded(info: RunRecord, names: set[str]) -> dict:
    """The run's datasets ``names`` that are on disk: name → (scenario, scans), each read once."""
    out = {}
    for n, d in info.paths.items():
        if n not in names:
            continue
        try:
            out[n] = load_dataset(str(d))
        except (OSError, TflocError):
            continue
    return out


def maps_of(info: RunRecord, names: set[str]) -> dict:
    """The maps of the run's datasets ``names`` that are on disk (each read once per process)."""
    return {n: map_for(sc, next(iter(scans.values()))) for n, (sc, scans) in _loaded(info, names).items() if scans}


def write_report(run_dir: str | Path, thresholds: Thresholds | None = None, *,
                 headline: list[HeadlineRow] | None = None, note: str = "",
                 landscapes: list[LandscapePanel] = (), stale_code: list[str] | None = None,
                 with_figures: bool = True) -> ReportFiles:
    """Write report.md and figures/*.png into ``run_dir`` from its rows and derived tables;
    returns their paths. ``thresholds``: re-score under other thresholds than the run's (the
    tables are then the caller's, derived under them); ``headline``: the rows to open with
    (default: ``headline.csv``); ``note``: why the run has no current truth-free verdict;
    ``landscapes``: ``tf``'s objective around a few scans, drawn with its section; ``stale_code``:
    the labels whose rows this checkout's code would not make (``None``: not checked). Sequence
    datasets get the tracking section; global ones the global section; the others the rest."""
    run_dir = Path(run_dir)
    rd = RunDir(run_dir)
    df, info = rd.results(), rd.info()
    thr = thresholds or info.thresholds
    names = list(df["dataset"].unique())
    seq, glob = info.datasets_in(names, SEQUENCE), info.datasets_in(names, GLOBAL)
    prepared = prepare(df, thr)
    rows = headline if headline is not None else rd.read(HEADLINE)
    tf = load_truth_free(rd, sorted(seq), note)
    top = headline_section(rows, thr, tf.note)
    scenarios = {n: sc for n, (sc, _) in _loaded(info, seq | glob).items()}
    tracking = ""
    if seq:
        from .tracking import tracking_section

        maps = maps_of(info, seq) if with_figures else {}
        tracking = tracking_section(rd, df[df["dataset"].isin(seq)], scenarios, maps, thr, figures=with_figures)
        blind = sorted(n for n in seq if not prepared.loc[prepared["dataset"] == n, "truth"].any())
        tracking += "\n" + truth_free_section(tf, blind)
    if glob:
        from .relocalization import relocalization_section

        tracking = relocalization_section(rd, df[df["dataset"].isin(glob)], thr) + "\n" + tracking
    if df["dataset"].isin(seq | glob).all():
        report = rd.report
        report.write_text("\n".join([header(run_dir, info, prepared, thr, set(), stale_code), top, tracking]))
        return ReportFiles(report, ())
    p = prepare(df[~df["dataset"].isin(seq | glob)], thr)
    s2s = info.datasets_in(list(p["dataset"].unique()), SCAN_TO_SCAN)
    paper = {d: s for d, s in info.paper_scenarios().items() if d in set(p["dataset"])}
    order = label_order(info, p)
    sweep = len(order) > MANY_MATCHERS  # a parameter sweep: compare each label with the first only
    pt = rd.frame(PAIRED)
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
        landscape = landscape_section(*draw_landscapes(run_dir, list(landscapes)))
    report = rd.report
    text = render(run_dir, info, p, thr, s2s, figs, pt, failures, landscape, line_labels, sweep, paper, top,
                  stale_code)
    report.write_text(text + ("\n" + tracking if tracking else ""))
    return ReportFiles(report, tuple(figs))
