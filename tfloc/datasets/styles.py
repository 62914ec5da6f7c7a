"""Map styles of the real logs as benchmark datasets: ``real-<log>-<style>``.

Every style of a log is built from the same corrected scans (:mod:`tfloc.maps.styles`) on the
same cell frame as the as-built grid, and every style's dataset holds the same rows: every
``SUBSAMPLE``-th scan of ``real-<log>-scan-to-map`` (the scans, truth, initial poses and groups
of that dataset, unchanged), so a matcher's success can be compared style by style, scan by
scan. ``scenario.json`` carries ``"axis": {"log": ..., "style": ...}`` for the report.
"""

from __future__ import annotations

from pathlib import Path

from tfloc.io.rosmap import write_exported_map, write_ros_map
from tfloc.io.scenario import write_scenario
from tfloc.maps import styles as st
from tfloc.maps.build import scan_counts

from .protocol import DEFAULT_SEED, Perturbation
from .real import REAL_LOGS, scan_to_map

#: Every SUBSAMPLE-th scan of each log (Intel 228, MIT CSAIL 102, ACES 110 scans per style).
SUBSAMPLE = 4
#: The styles, in report order.
STYLES = ("as-built", "hits-only", "thick-1", "thick-2", "cartographer", "gmapping", "incomplete")
DESCRIPTIONS = {
    "as-built": "tfloc's own grid (hit counting with free-space carving, occupied if > 25 % of the "
                "beams reaching a cell end there): the map of real-<log>-scan-to-map",
    "hits-only": "occupied where >= 2 returns ended in a cell, no free-space carving, every other "
                 "cell free (a binary image, map_saver thresholds)",
    "thick-1": "the as-built grid with every occupied region grown by 1 cell (5 cm)",
    "thick-2": "the as-built grid with every occupied region grown by 2 cells (10 cm)",
    "cartographer": "a Cartographer-style probability grid (hit 0.55 / miss 0.49 odds, clamped to "
                    "[0.1, 0.9]) written with grey values as cartographer_ros exports it (unknown 128) "
                    "and read as map_server does (trinary, 0.65 / 0.196: grey walls are unknown)",
    "gmapping": "GMapping's map (occupied if > 25 % of the beams reaching a cell end there, every other "
                "reached cell free) as ROS map_saver writes it (0 / 254 / 205, trinary)",
    "incomplete": "the as-built grid without the 10 % least-observed occupied cells (made unknown)",
}


def build_styles(real: Path, out: Path, seed: int = DEFAULT_SEED, resolution: float = 0.05) -> list[Path]:
    """Write ``out/scenarios/real-<log>-<style>`` for every log and style, and the style maps
    ``out/maps/styles/real-<log>-<style>.yaml|.png`` (the as-built style uses
    ``out/maps/real-<log>.yaml``, written by :func:`tfloc.datasets.real.build_all`)."""
    real, out = Path(real), Path(out)
    cfg = Perturbation(seed=seed)
    made = []
    for key, log_rel, laser, no_return in REAL_LOGS:
        grid, rows = scan_to_map(real / log_rel, laser, resolution, cfg, no_return)
        R = [r.ranges for r in rows]
        P = [r.true.as_array() for r in rows]
        counts = scan_counts(R, P, laser, resolution)
        subset = rows[::SUBSAMPLE]
        name = grid.name
        maps = {"as-built": out / "maps" / f"real-{key}.yaml"}
        if not maps["as-built"].exists():
            write_ros_map(grid, maps["as-built"])
        styled = out / "maps" / "styles"
        maps["hits-only"] = write_exported_map(st.hits_only(counts, name=f"{name}-hits-only"),
                                               styled / f"real-{key}-hits-only.yaml", "map_saver")
        for k in (1, 2):
            maps[f"thick-{k}"] = write_ros_map(st.thickened(grid, k), styled / f"real-{key}-thick-{k}.yaml",
                                               image_suffix=".png")
        maps["cartographer"] = write_exported_map(st.cartographer(counts, name=f"{name}-cartographer"),
                                                  styled / f"real-{key}-cartographer.yaml", "cartographer")
        maps["gmapping"] = write_exported_map(st.gmapping(counts, name=f"{name}-gmapping"),
                                              styled / f"real-{key}-gmapping.yaml", "map_saver")
        maps["incomplete"] = write_ros_map(st.incomplete(grid, counts), styled / f"real-{key}-incomplete.yaml",
                                           image_suffix=".png")
        for style in STYLES:
            ds = f"real-{key}-{style}"
            made.append(write_scenario(
                out / "scenarios" / ds, ds, maps[style], laser, subset,
                description=(f"Map style '{style}' of the {key} log: {DESCRIPTIONS[style]}. The rows are "
                             f"every {SUBSAMPLE}th scan of real-{key}-scan-to-map ({len(subset)} of "
                             f"{len(rows)}; scans, truth, initial poses and groups unchanged)."),
                axis={"log": key, "style": style},
                generator={"command": "tfloc real-data", "seed": seed, "resolution_m": resolution,
                           "clearance_m": cfg.clearance_m, "subsample": SUBSAMPLE},
                source={"files": [f"data/real/{log_rel}"], "provenance": "data/real/*/PROVENANCE.md"}))
    return made
