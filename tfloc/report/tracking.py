"""The tracking section of a report: one table per sequence set and figures, drawn from a run's
rows and the tracking tables derived from them (``tracking.csv``, ``kidnap.csv``, ``start.csv``:
:mod:`tfloc.evaluation.sequences`, written by :mod:`tfloc.harness.derive`).

Input: the estimate rows of sequence datasets (one row per scan and matcher, each (dataset,
matcher)'s rows in scan order as the tracking loop writes them), the datasets' scenarios and the
run directory's store.
A **sequence set** is the datasets of one condition (``scenario.json`` ``set``, else
``condition.name``: easy, rate-1hz, …, real); its table has one row per matcher (dead reckoning, ``odometry``, included as
the floor): the tracked share pooled over the set's scans with a 95 % bootstrap interval over
sequences (where the set has several), losses, recoveries and unrecovered losses summed over
sequences, the longest lost stretch, APE translation RMSE pooled over scans (cm), RPE per metre
(mean over sequences, cm/m) and the median CPU ms per scan. Definitions:
:mod:`tfloc.evaluation.trajectory`. Figures: each sequence's trajectories drawn on the map per
matcher, the distance error over distance travelled, and each tracker's first jumps
(:mod:`tfloc.report.jumps`). Sets whose sequences have kidnap events
(``scenario.json`` ``"kidnaps"``) get a kidnap table too (:func:`kidnap_tables`, from
``kidnap.csv``). Sets where a tracker starts without a pose (its first row's ``info`` says so)
get a start table (:func:`start_tables`, from ``start.csv``).
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd

from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.global_start import SETTLE_M, SETTLE_SCANS
from tfloc.evaluation.kidnap import HOLD, WITHIN, median_scans
from tfloc.evaluation.metrics import has_truth
from tfloc.evaluation.trajectory import LOST_DIST_M, LOST_ORIENT_DEG, pooled_share
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import Scenario
from tfloc.io.tables import KIDNAP, START, TRACKING

from .jumps import fig_jumps
from .mdtable import num, table
from .tracking_figures import DEAD_RECKONING, fig_error_distance, fig_trajectories, order

DEFAULT = Thresholds()


def _cpu_ms(df: pd.DataFrame) -> dict[tuple[str, str], np.ndarray]:
    """Per (dataset, tracker), its CPU per step (ms) along the sequence."""
    return {k: g["cpu_s"].to_numpy(float) * 1e3 for k, g in df.groupby(["dataset", "matcher"], sort=False)}


def condition_table(s: pd.DataFrame, cpu_ms: dict[tuple[str, str], np.ndarray]) -> str:
    """The markdown table of one sequence set (rows of ``tracking.csv``; ``cpu_ms``: each
    (dataset, tracker)'s CPU per step)."""
    rows = []
    for m in order(s["matcher"]):
        g = s[s["matcher"] == m]
        share, lo, hi = pooled_share(g["n_tracked"], g["n_truth"])
        ci = "" if math.isnan(lo) else f" [{100 * lo:.1f}, {100 * hi:.1f}]"
        n = g["n_truth"].to_numpy(float)
        ape = math.sqrt(float((n * g["ape_rmse_m"].to_numpy(float) ** 2).sum() / n.sum())) if n.sum() else math.nan
        cpu = np.concatenate([cpu_ms.get((d, m), np.array([])) for d in g["dataset"]]) if len(g) else np.array([])
        cpu = cpu[np.isfinite(cpu)]
        jumps = "—" if m == DEAD_RECKONING else f"{int(g['jumps'].sum())} ({num(g['max_jump_m'].max(), 2)})"
        rows.append([m, f"{100 * share:.1f}{ci}", int(g["losses"].sum()), int(g["recoveries"].sum()),
                     int(g["unrecovered"].sum()), num(g["longest_lost_m"].max(), 1), num(100 * ape, 1),
                     num(100 * g["rpe_trans_m_per_m"].mean(), 2), jumps,
                     "—" if m == DEAD_RECKONING or not cpu.size else num(float(np.median(cpu)), 2)])
    return table(["matcher", "tracked % [95 % CI over sequences]", "losses", "recoveries",
                  "unrecovered", "longest lost (m)", "APE RMSE (cm)", "RPE (cm/m)",
                  "jumps > 1 m (largest, m)", "CPU ms/scan (median)"], rows)


def tracking_tables(s: pd.DataFrame, cpu_ms: dict[tuple[str, str], np.ndarray],
                    datasets: dict[str, Scenario] | None = None) -> str:
    """One table per sequence set, each headed with its sequences, scans and metres; a set whose
    sequences run on different maps (different buildings) also gets one table per sequence."""
    parts = []
    for cond, g in s.groupby("condition", sort=True):
        maps = {str(datasets[d].map_path) for d in g["dataset"] if datasets and d in datasets}
        if len(maps) > 1:
            for ds, one in g.groupby("dataset", sort=False):
                parts.append(_set_table(f"{cond}: {ds}", one, cpu_ms))
        parts.append(_set_table(cond, g, cpu_ms))
    return "\n".join(parts)


def _set_table(cond: str, g: pd.DataFrame, cpu_ms: dict[tuple[str, str], np.ndarray]) -> str:
    """The heading and table of one sequence set (or one sequence)."""
    seqs = g.drop_duplicates("dataset")
    scored, steps = int(seqs["n_truth"].sum()), int(seqs["n_scans"].sum())
    scans = f"{scored} scans" if scored == steps else f"{steps} scans, {scored} of them with truth (scored)"
    return (f"**{cond}** ({len(seqs)} sequence{'s' * (len(seqs) != 1)}: {', '.join(seqs['dataset'])}; "
            f"{scans}, {seqs['distance_m'].sum():.0f} m)\n\n" + condition_table(g, cpu_ms))


def kidnap_tables(ev: pd.DataFrame) -> str:
    """One markdown table per kidnapped set (rows of ``kidnap.csv``): per matcher the
    events, those relocalized within 20 scans, the median scans to relocalize ("never" counted
    as infinitely many), false relocalizations and the tracked share (pooled over sequences)."""
    parts = []
    for cond, g in ev.groupby("set", sort=True):
        rows = []
        for m in order(g["matcher"]):
            h = g[g["matcher"] == m]
            n = [None if math.isnan(v) else int(v) for v in h["scans_to_relocalize"]]
            ok = sum(v is not None and v <= WITHIN for v in n)
            med = median_scans(n)
            rows.append([m, len(n), f"{ok}/{len(n)}", "never" if math.isinf(med) else num(med, 0),
                         int(h["false_relocalizations"].sum()),
                         num(100 * float(h["tracked"].dropna().mean()), 1)])
        seqs = g.drop_duplicates("dataset")["dataset"]
        parts.append(f"**{cond}: kidnap events** ({len(seqs)} sequence{'s' * (len(seqs) != 1)}: "
                     f"{', '.join(seqs)})\n\n" + table(
                         ["matcher", "events", f"relocalized within {WITHIN} scans",
                          "median scans to relocalize", "false relocalizations",
                          "tracked % (mean over sequences)"], rows))
    return "\n".join(parts)


def start_tables(st: pd.DataFrame) -> str:
    """One markdown table per set of ``start.csv``: per matcher its start (no pose or
    given), the sequences it converged on within the start window, scans to converge per
    sequence and their median ("never" counted as infinitely many), and the sequences where it
    first settled on a wrong place."""
    parts = []
    for cond, g in st.groupby("set", sort=True):
        seqs = sorted(g["dataset"].unique())
        rows = []
        for m in order(g["matcher"]):
            h = g[g["matcher"] == m].set_index("dataset").reindex(seqs)
            n = [None if not np.isfinite(v) else int(v) for v in h["scans_to_converge"].to_numpy(float)]
            med = median_scans(n)
            wrong = [d for d, w, s in zip(seqs, h["settled_wrong"], h["settled"], strict=True)
                     if bool(w) and np.isfinite(s)]
            rows.append([m, "none" if bool(h["no_pose"].fillna(False).any()) else "given",
                         f"{sum(v is not None for v in n)}/{len(n)}",
                         " / ".join("never" if v is None else str(v) for v in n),
                         "never" if math.isinf(med) else num(med, 0),
                         f"{len(wrong)}/{len(n)}" + (f" ({', '.join(wrong)})" if wrong else "")])
        window = ", ".join(f"{d} {int(w)}" for d, w in g.drop_duplicates("dataset").sort_values("dataset")[
            ["dataset", "window"]].to_numpy())
        parts.append(f"**{cond}: the start** ({len(seqs)} sequence{'s' * (len(seqs) != 1)}; start window in "
                     f"scans, to the first kidnap or the end: {window})\n\n" + table(
                         ["matcher", "start pose", "converged", "scans to converge (per sequence, as listed)",
                          "median scans to converge", "first settled on a wrong place"], rows, "llrrrl"))
    return "\n".join(parts)


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("_") or "x"


def own_score_table(df: pd.DataFrame, thresholds: Thresholds = DEFAULT) -> str:
    """Where a tracker reports its own score per scan (``info["score"]``, lower is better, e.g.
    ``tf-plus-recover``'s residual in metres): its percentiles over the scans it tracked (within
    the thresholds) and over the scans it had lost (above 0.5 m or 10°), per matcher. The truth
    is read here, to choose a tracker's own "lost" rule on a development split, never by it."""
    rows = []
    for m, g in df.groupby("matcher", sort=False):
        score = g["info"].map(lambda t: json.loads(t or "{}").get("score", np.nan)).to_numpy(float)
        if not np.isfinite(score).any():
            continue
        d, o = g["dist_err_m"].to_numpy(float), np.degrees(g["orient_err_rad"].to_numpy(float))
        ok = thresholds.success(d, np.radians(o)) & np.isfinite(score)
        lost = ((d > LOST_DIST_M) | (o > LOST_ORIENT_DEG)) & np.isfinite(score)
        pct = lambda v, q: " / ".join(f"{x:.4f}" for x in np.percentile(v, q)) if v.size else "–"  # noqa: E731
        rows.append([f"`{m}`", str(int(ok.sum())), pct(score[ok], [50, 90, 99, 100]),
                     str(int(lost.sum())), pct(score[lost], [0, 1, 10, 50])])
    if not rows:
        return ""
    return ("\n**The trackers' own scores** (`info.score`, lower is better): percentiles over the "
            "scans tracked and over the scans lost, read against the truth\n\n"
            + table(["matcher", "tracked scans", "score p50 / p90 / p99 / max", "lost scans",
                     "score min / p1 / p10 / p50"], rows, "lrlrl") + "\n")


#: Cartographer on the MIT CSAIL relations (Hess et al., ICRA 2016, Table II; data/real/README.md)
CARTOGRAPHER_CSAIL = ("Cartographer (Hess et al. 2016, Table II)", 0.0319, 0.0363, 0.369, 0.365)


def relations_tables(df: pd.DataFrame, datasets: dict[str, Scenario]) -> str:
    """For every sequence that names a relations file (``scenario.json`` ``"relations"``), the
    relation errors of each matcher's tracked trajectory (Kümmerle et al. 2009; mean ± sample
    std, every relation whose two stamps are rows), beside the published figures."""
    from tfloc.evaluation.relations import tracked_relation_stats
    from tfloc.io.relations import read_relations, relations_path
    from tfloc.io.scenario import read_scans

    from .relations_note import PUBLISHED_CSAIL

    parts = []
    for ds, g in df.groupby("dataset", sort=False):
        sc = datasets.get(ds)
        path = relations_path(sc) if sc is not None else None
        if path is None:
            continue
        relations = read_relations(path)
        stamp = {s.scan_id: s.stamp for s in read_scans(sc)}
        rows = []
        for m in order(g["matcher"]):
            r = g[g["matcher"] == m]
            st = r["scan_id"].map(stamp).to_numpy(float)
            est = r[["est_x", "est_y", "est_theta"]].to_numpy(float)
            x = tracked_relation_stats(st, est, relations)
            rows.append([f"`{m}`", f"{x['n']} of {x['n_relations']}", f"{x['trans_mean_m']:.3f} ± {x['trans_std_m']:.3f}",
                         num(x["trans_max_m"], 2), f"{x['rot_mean_deg']:.2f} ± {x['rot_std_deg']:.2f}",
                         num(x["rot_max_deg"], 1)])
        label, tm, ts, rm, rs = CARTOGRAPHER_CSAIL
        rows.append([label, "published", f"{tm:.4f} ± {ts:.4f}", "–", f"{rm:.3f} ± {rs:.3f}", "–"])
        for label, tm, ts, mx in PUBLISHED_CSAIL:
            rows.append([label, "published", f"{tm:.3f} ± {ts:.3f}", num(mx, 2) if mx else "–", "–", "–"])
        parts.append(f"\n**{ds}: relation errors of the tracked trajectory** (the relations of "
                     f"`{path.name}`: each estimated relative pose between the two stamps against the "
                     "relation; translational m, rotational °, mean ± std; the published rows are SLAM "
                     "systems' trajectories, which use every scan and loop closures)\n\n"
                     + table(["matcher", "relations", "translational (m)", "max (m)", "rotational (°)",
                              "max (°)"], rows, "llrrrr"))
    return "\n".join(parts)


#: trackers with a rule of their own for an odometry increment they doubt (stated in the tables,
#: since the harness's prediction has none and no peer's package ships one)
OWN_ODOMETRY_RULES = {
    "tf-plus-track": "an increment the robot cannot have made between two scans (0.5 m or 30°) is "
                     "also tried as no motion, from the last estimate, the better answer winning",
}


def _own_odometry_rules(df: pd.DataFrame) -> list[str]:
    """One line per tracker in ``df`` (or a preset of it, ``name[...]``/``name-...``) that
    handles a doubted odometry increment itself: its own feature, not the harness's."""
    names = {str(m) for m in df["matcher"].unique()} if "matcher" in df else set()
    lines = [f"`{base}`'s own feature: {rule}; no other tracker here has such a rule.\n"
             for base, rule in OWN_ODOMETRY_RULES.items()
             if any(n == base or n.startswith((base + "[", base + "-")) for n in names)]
    return lines


def tracking_section(rd: RunDir, df: pd.DataFrame, datasets: dict[str, Scenario], maps: dict[str, object],
                     thresholds: Thresholds = DEFAULT, figures: bool = True) -> str:
    """The markdown of the tracking section (tables, then figures written under
    ``RUN/figures/tracking/``); ``df``: the rows of the run's sequence datasets; ``maps``:
    dataset name → its map, for the figures. A dataset without truth gets no truth-based figure
    or table: its trajectories and jumps only (the truth-free verdict ranks it,
    :mod:`tfloc.report.truthfree`)."""
    out_dir = rd.path
    truth = has_truth(df).groupby(df["dataset"]).any()
    blind = [d for d in df["dataset"].unique() if not truth.get(d, False)]
    everything, df = df, df[~df["dataset"].isin(blind)]
    scores = rd.frame(TRACKING)
    s = scores[scores["dataset"].isin(set(df["dataset"]))]
    text = ["## Tracking\n",
            "Each sequence tracked scan by scan from the last estimate composed with the odometry "
            "(no reset); truth only for scoring. tracked = within "
            f"{100 * thresholds.dist_m:.0f} cm and {thresholds.orient_deg:g}°; a loss = the error "
            "goes above 0.5 m or 10°; a recovery = back within the thresholds by itself; APE/RPE by "
            "evo with no alignment (map frame), over the scans with truth; a jump = an estimate more "
            "than 1 m from the prediction it started from (every scan); `odometry` = dead reckoning, "
            "the floor. Every tracker gets the same odometry, each increment composed whole.\n",
            *_own_odometry_rules(everything),
            tracking_tables(s, _cpu_ms(df), datasets) if len(df) else "", relations_tables(df, datasets),
            own_score_table(df, thresholds) if len(df) else ""]
    if blind:
        text.append(f"Without ground truth: {', '.join(blind)}: no truth-based figure; ranked by the "
                    "truth-free verdict (below); their trajectories and first jumps are drawn.\n")
    ev = rd.frame(KIDNAP)
    if len(ev):
        text += ["\nKidnap events (the robot moved 5–20 m and turned, unseen by the odometry): "
                 "relocalized = the first scan after the event within the thresholds that stays "
                 "there for 3 scans (never: not before the next event or the end); a false "
                 "relocalization = the estimate jumps > 1 m from its prediction, away from a "
                 "correct pose to a wrong one. Per event: `kidnap.csv`.\n", kidnap_tables(ev)]
    st = rd.frame(START)
    if len(st):
        text += [f"\nThe start, for sets where a tracker starts without a pose (its first row says "
                 "`\"start\": \"global\"`: it ignored the first row's pose; the others, given it, are "
                 "the reference): converged = the first scan within the thresholds that stays there "
                 f"for {HOLD} scans, before the first kidnap (never: not before it); settled = the "
                 f"estimate stays within {SETTLE_M:g} m of one place (carried along by the robot's true "
                 f"motion) for {SETTLE_SCANS} scans; on a wrong place when that place is more than "
                 f"{LOST_DIST_M:g} m or {LOST_ORIENT_DEG:g}° off. Per sequence: `start.csv`.\n",
                 start_tables(st)]
    if figures:
        fig_dir = Path(out_dir) / "figures" / "tracking"
        for ds, g in everything.groupby("dataset", sort=False):
            sc = datasets.get(ds)
            if sc is None or ds not in maps:
                continue
            a = fig_trajectories(sc, maps[ds], g, fig_dir / f"{_safe(ds)}-trajectories.png")
            rel = lambda p: p.relative_to(out_dir).as_posix()  # noqa: E731
            text.append(f"\n![{ds} trajectories]({rel(a)})\n")
            if ds not in blind:
                b = fig_error_distance(sc, g, fig_dir / f"{_safe(ds)}-error.png")
                text.append(f"![{ds} error over distance]({rel(b)})\n")
            j = fig_jumps(ds, maps[ds], g, fig_dir / f"{_safe(ds)}-jumps.png")
            if j is not None:
                text.append(f"\n![{ds}: the first jumps of each tracker]({rel(j)})\n")
    return "\n".join(text)
