"""The scaling study's README (tables, slopes, one sentence per matcher) and its figure.

:func:`render` draws them from the study's tables (``scaling.csv``, ``prep.csv``, ``skips.csv``
and the derived ``levels.csv`` and ``slopes.csv``: :func:`tfloc.harness.scaling.derive_scaling`)
and its record (the configuration and how it was made: :func:`provenance`); the study itself is
``tfloc scaling`` (:mod:`tfloc.harness.scaling`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from tfloc.core.run import RunRecord, Session
from tfloc.evaluation.scaling import GROWS_SLOPE, prep_slope_table

from .figures import colours
from .mdtable import num, table

AXIS_TITLES = {("area", "vector"): "map area, vector map", ("area", "grid"): "map area, 5 cm grid",
               ("beams", "vector"): "beam count (office, vector)",
               ("offset", "vector"): "initial distance offset (office, vector)"}
#: The linear slope's unit per axis: (label, factor applied to ms per unit of size).
LINEAR_UNIT = {"area": ("ms per 10⁴ m²", 1e4), "beams": ("ms per 100 beams", 100.0),
               "offset": ("ms per m", 1.0)}
AXIS_X = {"area": "map extent (m²)", "beams": "beams per scan", "offset": "offset bin centre (m)"}


def _cell(levels: pd.DataFrame, axis: str, kind: str, matcher: str, level: str) -> str:
    g = levels[(levels["axis"] == axis) & (levels["kind"] == kind) & (levels["matcher"] == matcher)
               & (levels["level"] == level)]
    if g.empty:
        return "—"
    r = g.iloc[0]
    return f"{num(r['cpu_ms_median'], 2)} ({100 * r['success']:.0f} %)"


def level_section(levels: pd.DataFrame, axis: str, kind: str, slopes: pd.DataFrame) -> str:
    """One table: a row per matcher, a column per level (median CPU ms and success), the slope."""
    sub = levels[(levels["axis"] == axis) & (levels["kind"] == kind)]
    if sub.empty:
        return ""
    order = sub.drop_duplicates("level").sort_values("size")
    cols = list(order["level"])
    sizes = list(order["size"])
    n = int(sub["n"].max())
    unit, factor = LINEAR_UNIT[axis]
    head = ["matcher"] + [f"{lv} ({num(s, 0)})" if axis != "offset" else lv for lv, s in
                          zip(cols, sizes, strict=True)] + ["slope", "grows?", unit]
    body = []
    for m in sorted(sub["matcher"].unique()):
        s = slopes[(slopes["axis"] == axis) & (slopes["kind"] == kind) & (slopes["matcher"] == m)]
        slope = float(s["slope"].iloc[0]) if len(s) else math.nan
        linear = float(s["ms_per_unit"].iloc[0]) * factor if len(s) else math.nan
        body.append([m] + [_cell(levels, axis, kind, m, lv) for lv in cols]
                    + [num(slope, 2), _verdict(slope), f"{linear:+.2f}" if math.isfinite(linear) else "—"])
    title = AXIS_TITLES.get((axis, kind), f"{axis}, {kind}")
    return (f"### CPU per scan against {title}\n\nMedian CPU ms per scan (success rate), n = {n} scans "
            f"per table cell; column heads: level ({AXIS_X[axis]}); slope of log(median CPU) against "
            f"log({AXIS_X[axis].split(' (')[0]}); last column: the least-squares slope of the median "
            f"itself ({unit}), the additive part a log–log slope hides while it is small.\n\n" + table(head, body) + "\n")


def _verdict(slope: float) -> str:
    if not math.isfinite(slope):
        return "—"
    return "grows" if slope > GROWS_SLOPE else "flat"


def sentences(slopes: pd.DataFrame) -> list[str]:
    """One plain sentence per matcher: whether its per-scan cost grows with each axis."""
    out = []
    for m in sorted(slopes["matcher"].unique()):
        parts = []
        for axis, kind, what in (("area", "vector", "a vector map's area"), ("area", "grid", "a grid map's area"),
                                 ("beams", "vector", "the beam count"), ("offset", "vector", "the initial offset")):
            s = slopes[(slopes["axis"] == axis) & (slopes["kind"] == kind) & (slopes["matcher"] == m)]
            if s.empty or not math.isfinite(float(s["slope"].iloc[0])):
                continue
            r = s.iloc[0]
            verb = "grows with" if r["slope"] > GROWS_SLOPE else "does not grow with"
            parts.append(f"{verb} {what} (slope {r['slope']:.2f}; {num(r['first_ms'], 2)} → "
                         f"{num(r['last_ms'], 2)} ms)")
        if parts:
            out.append(f"- **{m}**: its CPU per scan " + "; ".join(parts) + ".")
    return out


def prep_section(prep: pd.DataFrame, prep_slopes: pd.DataFrame) -> str:
    """Preparation per map: CPU s and retained memory (MB) per matcher and map size, and slopes."""
    if prep.empty:
        return ""
    out = []
    for kind in prep["kind"].unique():
        sub = prep[prep["kind"] == kind]
        sizes = sorted(sub["size"].unique())
        head = ["matcher"] + [f"{num(s, 0)} m²" for s in sizes] + ["time slope", "memory slope"]
        body = []
        for m in dict.fromkeys(sub["matcher"]):
            g = sub[sub["matcher"] == m].set_index("size")
            cells = []
            for s in sizes:
                if s not in g.index:
                    cells.append("—")
                    continue
                r = g.loc[s]
                cells.append(r["status"] if r["status"] != "ok" else
                             f"{num(r['prep_cpu_s'], 2)} s / {num(r['rss_delta_mb'], 0)} MB "
                             f"({num(r['peak_mb'], 0)})")
            ps = prep_slopes[(prep_slopes["kind"] == kind) & (prep_slopes["matcher"] == m)]
            ts = float(ps["time_slope"].iloc[0]) if len(ps) else math.nan
            ms = float(ps["memory_slope"].iloc[0]) if len(ps) else math.nan
            body.append([m, *cells, num(ts, 2), num(ms, 2)])
        what = (f"{int(sub['cells'].max()):,} cells at the largest size" if kind == "grid"
                else f"{int(sub['segments'].max()):,} segments at the largest size")
        out.append(f"### Map preparation, {kind} maps ({what})\n\nCPU seconds of `prepare(problem)` / "
                   f"resident memory it left behind (MB: RSS after minus before, each after a garbage "
                   f"collection and `malloc_trim`; psutil) and, in brackets, its peak above the memory "
                   f"before (MB: VmHWM, reset through `/proc/self/clear_refs`). Both count what "
                   f"tracemalloc does not see (numba, open3d, small_gicp, Karto); each matcher "
                   f"prepares its own copy of the map. `(map)`: building the map itself "
                   f"(tiling{', rasterising at 5 cm' if kind == 'grid' else ''}).\n\n"
                   + table(head, body) + "\n")
    return "\n".join(out)


#: A matcher whose system time exceeds this share of its CPU time at some level is named.
SYS_SHARE_NOTE = 0.2


def system_time_note(levels: pd.DataFrame) -> str:
    """A sentence naming the matchers whose CPU time is largely system time at some level (the
    kernel zeroing fresh pages of large temporaries: it varies with the allocator's state and the
    machine's load more than user time does)."""
    if "sys_share" not in levels:
        return ""
    hi = levels[levels["sys_share"] > SYS_SHARE_NOTE]
    if hi.empty:
        return (f"**System time.** No matcher spent more than {100 * SYS_SHARE_NOTE:.0f} % of its "
                f"CPU time in the kernel at any level.")
    worst = hi.sort_values("sys_share", ascending=False).drop_duplicates("matcher")
    items = ", ".join(f"{r.matcher} {100 * r.sys_share:.0f} % ({r.axis} {r.kind} {r.level})"
                      for r in worst.itertuples())
    return (f"**System time.** CPU time is user plus system time. Matchers with more than "
            f"{100 * SYS_SHARE_NOTE:.0f} % system time at some level (the largest share): {items}. "
            f"System time here is mostly the kernel handing out fresh pages for large temporary "
            f"arrays; it depends on the allocator's state and the machine's load, so these medians "
            f"vary more between runs than the others (`levels.csv`: `sys_share`).")


def changed_outcomes(rows: pd.DataFrame) -> str:
    """A sentence on the area axis's scans whose success differs between the smallest map and a
    larger one (the scans are the same: only the map around them grew), with their errors."""
    a = rows[rows["axis"] == "area"]
    if a.empty or a["level"].nunique() < 2:
        return ""
    first = a.loc[a["size"] == a["size"].min()].set_index(["kind", "matcher", "scan_id"])
    rest = a.loc[a["size"] > a["size"].min()]
    base = first["success"].reindex(pd.MultiIndex.from_frame(rest[["kind", "matcher", "scan_id"]]))
    flip = rest[(rest["success"].to_numpy() != base.to_numpy())]
    if flip.empty:
        return ("**Success across sizes.** Every matcher answered every scan the same way (success "
                "or not) at every map size.")
    lost = flip[flip["success"] == 0]
    pairs = flip.groupby(["kind", "matcher"])["scan_id"].nunique()
    return (f"**Success across sizes.** The scans are the same at every size, yet "
            f"{int(pairs.sum())} (matcher, scan) pairs out of "
            f"{a.groupby(['kind', 'matcher'])['scan_id'].nunique().sum()} change outcome between the "
            f"one-tile map and a larger one ({len(lost)} rows lost, {len(flip) - len(lost)} gained; "
            f"by matcher: {', '.join(f'{m} {k} {n}' for (k, m), n in pairs.items())}). From 2 × 2 "
            f"tiles on, tile (0, 0) has neighbours 0.4 m behind its outline walls (a wall's "
            f"thickness): the median distance error of the lost rows is "
            f"{lost['dist_err_m'].median():.2f} m, i.e. a wall matched to the neighbour's parallel "
            f"wall. This is the larger map's geometry, not the study's scans; the costs are "
            f"compared on the same scans all the same.") if len(lost) else (
            f"**Success across sizes.** {int(pairs.sum())} (matcher, scan) pairs change outcome "
            f"between the one-tile map and a larger one, all gained.")


def write_readme(path: Path, rows: pd.DataFrame, levels: pd.DataFrame, slopes: pd.DataFrame,
                 prep: pd.DataFrame, prep_slopes: pd.DataFrame, skips: pd.DataFrame, config: dict,
                 provenance: dict) -> Path:
    """The study's README.md."""
    load0, load1 = provenance.get("loadavg_start", []), provenance.get("loadavg_end", [])
    lines = ["# Scaling study: CPU per scan against map area, beam count and initial offset", "",
             "Written by `tfloc scaling`; do not edit by hand: "
             f"`{provenance.get('command') or 'tfloc scaling'}` regenerates it.", "",
             "**Conditions.** One process pinned to one core "
             f"({provenance.get('cores')}), every library on one thread; per-scan CPU time "
             "(`time.process_time`, the harness's timer) of `localize` alone, matchers interleaved "
             "scan by scan (order rotated per scan), after `prepare` and an untimed warm-up. "
             f"Machine: {provenance.get('cpu', '?')}, Python {provenance.get('python', '?')}; "
             f"{_code(provenance.get('git'))}; "
             f"**the machine was shared** with other jobs (load average {load0} at the start, "
             f"{load1} at the end): CPU times are robust to that, wall times are not. Started "
             f"{provenance.get('started', '?')}, {provenance.get('wall_s', '?')} s wall"
             + (f", {provenance['cpu_s']} s CPU in all" if "cpu_s" in provenance else "")
             + (f" over {provenance['sessions']} sessions (resumed)." if provenance.get("sessions", 1) > 1
                else "."), "",
             "**Problems.** The office floor `" + str(config.get("map_path")) + "` tiled n × n "
             "(tiles 0.4 m apart, each closed by its own outline); scans simulated in tile (0, 0) "
             "(LMS200 model plus 1 cm noise, seeded), so the same scans at every map size. Initial "
             "poses from the paper protocol's sampler, scan k in offset cell k mod 9 (0–3 m, 0–15°). "
             "Beam axis: the same poses, 180° at 1°/0.5°/0.25° and 270° at 0.25°. Offset axis: "
             "the protocol's distance bins. Success: ≤ 10 cm and ≤ 2°. "
             f"Scans per level: {config.get('scans_per_level')} (area, beams), "
             f"{config.get('scans_per_offset_bin')} per offset bin.", "",
             f"**Verdict rule.** A slope of log(median CPU) against log(size) above {GROWS_SLOPE} = "
             "*grows* (×16 the area → ×1.74 the cost or more). Slopes are fitted on the level medians "
             "(least squares; the points are in the figure and in `levels.csv`).", "",
             f"**Budgets.** A matcher whose median at a level exceeded {config.get('budget_ms'):g} ms, "
             f"or whose preparation exceeded {config.get('prep_budget_s'):g} s CPU, was not run at the "
             "larger levels of that axis (listed below); its slope covers the levels it ran.", "",
             changed_outcomes(rows), "", system_time_note(levels), "",
             "![scaling](scaling.png)", "", "## Per matcher", "", *sentences(slopes), ""]
    for axis, kind in (("area", "vector"), ("area", "grid"), ("beams", "vector"), ("offset", "vector")):
        sec = level_section(levels, axis, kind, slopes)
        if sec:
            lines += [sec]
    lines += ["## Map preparation (apart from the per-scan cost)", "", prep_section(prep, prep_slopes)]
    grid = prep[(prep["kind"] == "grid") & (prep["status"] == "ok")]
    if not grid.empty:
        big = grid[grid["size"] == grid["size"].max()]
        cells = int(big["cells"].max())
        lines += [f"The largest grid ({num(big['size'].iloc[0], 0)} m² extent at 5 cm) has {cells:,} "
                  f"cells: its occupancy array alone is {cells * 4 / 2**20:.0f} MB (float32)."]
        tp = big[big["matcher"] == "tf-plus"]
        if len(tp):
            lines += [f"**`tf-plus` on the {num(big['size'].iloc[0], 0)} m² grid at 5 cm**: its "
                      f"preparation (the map's view: distance field, normals, wall surfaces, the "
                      f"pooled copy, the free-space test) takes {num(tp['prep_cpu_s'].iloc[0], 2)} s "
                      f"CPU and keeps {num(tp['rss_delta_mb'].iloc[0], 0)} MB resident (peak "
                      f"{num(tp['peak_mb'].iloc[0], 0)} MB above the memory before it), on top of the "
                      f"map itself."]
        lines += [""]
    if not skips.empty:
        lines += ["## Not run (budget)", "", table(["axis", "kind", "level", "matcher", "why"],
                                                   skips[["axis", "kind", "level", "matcher", "why"]].values.tolist()), ""]
    lines += ["## Files", "", "- `scaling.csv`: one row per (matcher, axis, level, scan): CPU and wall "
              "ms, errors, success.", "- `levels.csv`: medians per level; `slopes.csv`: the fits.",
              "- `prep.csv`: preparation per (matcher, map): CPU and wall s, retained RSS (MB).",
              "- `run.json`: the configuration, its fingerprint, the code, versions and machine, "
              "the sessions.", ""]
    path.write_text("\n".join(lines))
    return path


def _code(git: dict | None) -> str:
    """The code that made the study: its commit, and whether the tree had uncommitted changes."""
    if not git or not git.get("commit"):
        return "code not recorded"
    return f"code `{git['commit'][:7]}`" + (" with uncommitted changes" if git.get("dirty") else "")


def provenance(run: RunRecord) -> dict:
    """What the README says of how the study was made, from ``run.json``: the command, cores,
    machine, code, the first start, load averages, and wall and CPU seconds over its sessions."""
    sessions = run.sessions or (Session(),)
    total = {k: round(sum(float(getattr(s, k) or 0.0) for s in sessions), 1) for k in ("wall_s", "cpu_s")}
    cores = sessions[-1].cores
    return {"command": run.command, "cores": list(cores) if cores is not None else None, "cpu": run.machine.cpu,
            "python": run.machine.python, "git": run.git.to_dict(),
            "started": sessions[0].started, "loadavg_start": list(sessions[0].loadavg_start or []),
            "loadavg_end": list(sessions[-1].loadavg_end or []), "sessions": len(sessions), **total}


def render(out: Path, rows: pd.DataFrame, prep: pd.DataFrame, skips: pd.DataFrame, levels: pd.DataFrame,
           slopes: pd.DataFrame, run: RunRecord) -> None:
    """``scaling.png`` and ``README.md`` in ``out`` from the study's tables (``scaling.csv``,
    ``prep.csv``, ``skips.csv`` and the derived ``levels.csv``, ``slopes.csv``:
    :func:`tfloc.harness.scaling.derive_scaling`) and its record."""
    write_figure(out / "scaling.png", levels, slopes, prep)
    write_readme(out / "README.md", rows, levels, slopes, prep, prep_slope_table(prep), skips, dict(run.study),
                 provenance(run))


def _plain_ticks(ax) -> None:
    """Tick labels as plain numbers (2, 5, 10, 20) on log axes, not 2 × 10⁰."""
    from matplotlib.ticker import FuncFormatter, LogLocator

    fmt = FuncFormatter(lambda v, _: f"{v:g}")
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_formatter(fmt)
        axis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))
        axis.set_minor_formatter(fmt)


def write_figure(path: Path, levels: pd.DataFrame, slopes: pd.DataFrame, prep: pd.DataFrame) -> Path:
    """Log–log panels: CPU per scan against each axis (points = level medians, lines = fits), and
    preparation time and memory against map area."""
    panels = [k for k in AXIS_TITLES if not levels[(levels["axis"] == k[0]) & (levels["kind"] == k[1])].empty]
    matchers = sorted(levels["matcher"].unique())
    col = colours(matchers)
    n = len(panels) + (2 if not prep.empty else 0)
    ncol = 3
    nrow = max(1, math.ceil(n / ncol))
    fig = Figure(figsize=(5.2 * ncol, 4.0 * nrow))
    axes = fig.subplots(nrow, ncol, squeeze=False).ravel()
    for ax, (axis, kind) in zip(axes, panels, strict=False):
        sub = levels[(levels["axis"] == axis) & (levels["kind"] == kind)]
        for m in matchers:
            g = sub[sub["matcher"] == m].sort_values("size")
            if g.empty:
                continue
            ax.plot(g["size"], g["cpu_ms_median"], "o", color=col[m], ms=4)
            s = slopes[(slopes["axis"] == axis) & (slopes["kind"] == kind) & (slopes["matcher"] == m)]
            label = m
            if len(s) and math.isfinite(float(s["slope"].iloc[0])) and len(g) > 1:
                x = np.geomspace(g["size"].min(), g["size"].max(), 20)
                b = float(s["slope"].iloc[0])
                a = np.mean(np.log(g["cpu_ms_median"]) - b * np.log(g["size"]))
                ax.plot(x, np.exp(a + b * np.log(x)), "-", color=col[m], lw=1)
                label = f"{m} ({b:+.2f})"
            ax.plot([], [], "o-", color=col[m], label=label)
        ax.set(xscale="log", yscale="log", title=AXIS_TITLES[(axis, kind)], xlabel=AXIS_X[axis],
               ylabel="median CPU per scan (ms)")
        _plain_ticks(ax)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="best")
    rest = axes[len(panels):]
    done = prep[prep["status"] == "ok"] if not prep.empty else prep
    if not prep.empty:
        for ax, colname, ylabel in ((rest[0], "prep_cpu_s", "prepare CPU (s)"),
                                    (rest[1], "rss_delta_mb", "retained memory (MB)")):
            floor = 1e-3 if colname == "prep_cpu_s" else 1.0
            for (m, kind), g in done.groupby(["matcher", "kind"], sort=True):
                g = g.sort_values("size")
                y = g[colname].clip(lower=floor)
                c = "k" if m == "(map)" else col.get(m, "grey")
                ax.plot(g["size"], y, "o-" if kind == "grid" else "s--", color=c, ms=3, lw=1,
                        label=m if kind == "grid" else None)
            ax.set_ylim(bottom=floor * 0.8)
            ax.set(xscale="log", yscale="log", xlabel="map extent (m²)", ylabel=ylabel,
                   title=f"{ylabel.split(' (')[0]} per map (— grid, -- vector; floor {floor:g})")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=6, ncol=2, loc="best")
        rest = rest[2:]
    for ax in rest:
        ax.set_visible(False)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path
