"""The summary of a timing pass (:mod:`tfloc.harness.timing`): CPU time per matcher, side by side.

Per matcher over the sampled scans: median CPU ms with a bootstrap 95 % interval, p95 CPU ms,
median wall ms, the ratio of its median CPU time to the reference matcher's with a paired
bootstrap interval (resampling scans), and, when the run recorded CPU times, the run's median
CPU ms on the same scans and its ratio to the quiet re-timing (how far the run's own CPU times
were inflated by sharing the machine).

Comparing a re-timing with a committed pass (``tfloc timing RUN --verify``): per matcher its
median CPU ms then and now (:func:`verify_ratios`), and, where absolute CPU times do not compare
(another CPU model), its ratio to the reference matcher then and now (:func:`between_ratios`):
matchers timed side by side share the machine, so its speed cancels out of their ratios.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .stats import bootstrap_median, ratio_of_medians

TIMING_SUMMARY_COLUMNS = ["matcher", "n", "cpu_median_ms", "cpu_median_lo_ms", "cpu_median_hi_ms",
                          "cpu_p95_ms", "wall_median_ms", "ratio_to_reference", "ratio_lo", "ratio_hi",
                          "run_cpu_median_ms", "run_over_quiet"]
DEFAULT_REFERENCE = "tf-plus"


def reference_of(matchers: list[str], wanted: str | None = None) -> str:
    """The reference matcher: ``wanted`` if given, else ``tf-plus`` if present, else the first."""
    if wanted:
        if wanted not in matchers:
            raise ValueError(f"reference matcher {wanted!r} is not in the timing pass ({', '.join(matchers)})")
        return wanted
    return DEFAULT_REFERENCE if DEFAULT_REFERENCE in matchers else matchers[0]


def timing_summary(t: pd.DataFrame, reference: str, run: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per matcher (in the order they appear in ``t``), columns :data:`TIMING_SUMMARY_COLUMNS`.

    ``t`` holds the pass's rows (dataset, scan_id, matcher, cpu_ms, wall_ms); ``run`` the run's
    estimates (for ``cpu_s`` on the same scans), or None."""
    cpu = t.pivot_table(index=["dataset", "scan_id"], columns="matcher", values="cpu_ms", aggfunc="first")
    ref = cpu[reference]
    run_cpu = None
    if run is not None and "cpu_s" in run and run["cpu_s"].notna().any():
        r = run.assign(cpu_ms=1000.0 * run["cpu_s"].astype(float))
        run_cpu = r.pivot_table(index=["dataset", "scan_id"], columns="matcher", values="cpu_ms", aggfunc="first")
    rows = []
    for m in dict.fromkeys(t["matcher"]):
        g = t[t["matcher"] == m]
        pair = pd.concat([cpu[m], ref], axis=1, keys=["m", "ref"]).dropna()
        ratio, lo, hi = ratio_of_medians(pair["m"].to_numpy(), pair["ref"].to_numpy())
        c_lo, c_hi = bootstrap_median(g["cpu_ms"])
        row = {"matcher": m, "n": len(g), "cpu_median_ms": float(np.median(g["cpu_ms"])),
               "cpu_median_lo_ms": c_lo, "cpu_median_hi_ms": c_hi,
               "cpu_p95_ms": float(np.percentile(g["cpu_ms"], 95)), "wall_median_ms": float(np.median(g["wall_ms"])),
               "ratio_to_reference": ratio, "ratio_lo": lo, "ratio_hi": hi,
               "run_cpu_median_ms": np.nan, "run_over_quiet": np.nan}
        if run_cpu is not None and m in run_cpu:
            same = run_cpu[m].reindex(cpu.index).dropna()
            if len(same):
                row["run_cpu_median_ms"] = float(np.median(same))
                row["run_over_quiet"] = row["run_cpu_median_ms"] / float(np.median(cpu[m].reindex(same.index)))
        rows.append(row)
    return pd.DataFrame(rows, columns=TIMING_SUMMARY_COLUMNS)


VERIFY_COLUMNS = ["matcher", "n", "committed_ms", "now_ms", "ratio"]


def verify_ratios(committed: pd.DataFrame, now: pd.DataFrame) -> pd.DataFrame:
    """Per matcher (in ``now``'s order), its median CPU ms over the scans both passes timed, in the
    committed pass and now, and their ratio now / committed; columns :data:`VERIFY_COLUMNS`. Both
    frames hold a pass's rows (dataset, scan_id, matcher, cpu_ms)."""
    keys = ["dataset", "scan_id", "matcher"]
    both = now[keys + ["cpu_ms"]].merge(committed[keys + ["cpu_ms"]], on=keys, suffixes=("_now", "_then"))
    rows = []
    for m in dict.fromkeys(now["matcher"]):
        g = both[both["matcher"] == m]
        then = float(np.median(g["cpu_ms_then"])) if len(g) else np.nan
        cur = float(np.median(g["cpu_ms_now"])) if len(g) else np.nan
        rows.append({"matcher": m, "n": len(g), "committed_ms": then, "now_ms": cur,
                     "ratio": cur / then if then > 0 else np.nan})
    return pd.DataFrame(rows, columns=VERIFY_COLUMNS)


BETWEEN_COLUMNS = ["matcher", "n", "committed_to_ref", "now_to_ref", "ratio"]


def between_ratios(verified: pd.DataFrame, reference: str) -> pd.DataFrame:
    """The matchers' ratios to one another, committed and now, from :func:`verify_ratios`' table
    ``verified``: per matcher (in its order) its median CPU ms over ``reference``'s, in the
    committed pass (``committed_to_ref``) and now (``now_to_ref``), and ``ratio`` the one now over
    the one committed (unitless; NaN where a median is missing); columns :data:`BETWEEN_COLUMNS`.
    A machine uniformly ×f slower scales every median by f and leaves these ratios as they were.
    A ``reference`` not in ``verified`` is a :class:`ValueError`."""
    v = verified.set_index("matcher")
    if reference not in v.index:
        raise ValueError(f"reference matcher {reference!r} is not in the re-timing ({', '.join(v.index)})")
    ref_then, ref_now = (float(v.loc[reference, c]) for c in ("committed_ms", "now_ms"))
    out = pd.DataFrame({"matcher": v.index, "n": v["n"].to_numpy(),
                        "committed_to_ref": (v["committed_ms"] / (ref_then if ref_then > 0 else np.nan)).to_numpy(),
                        "now_to_ref": (v["now_ms"] / (ref_now if ref_now > 0 else np.nan)).to_numpy()})
    out["ratio"] = (out["now_to_ref"] / out["committed_to_ref"]).where(out["committed_to_ref"] > 0)
    return out[BETWEEN_COLUMNS]


def within(ratio: float, limit: float) -> bool:
    """Whether ``ratio`` lies within ×1/``limit``–×``limit`` (False for NaN)."""
    return 1.0 / limit <= ratio <= limit


def outside(table: pd.DataFrame, limit: float) -> list[str]:
    """The matchers of ``table`` (:func:`verify_ratios`' or :func:`between_ratios`') whose
    ``ratio`` lies outside ×1/``limit``–×``limit`` (or is NaN), in its order."""
    return [str(m) for m, r in zip(table["matcher"], table["ratio"], strict=True) if not within(float(r), limit)]
