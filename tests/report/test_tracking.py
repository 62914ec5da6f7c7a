"""The tracking section of a report: one table per sequence set with intervals over sequences,
dead reckoning as the floor, and the figures."""

from __future__ import annotations

import dataclasses

from _estimates import derive_tracking
from _paths import ROOT, SCEN

from tfloc.core.rows.tracking import TrackingRow
from tfloc.evaluation.sequences import sequence_scores
from tfloc.harness.track import dead_reckoning
from tfloc.io.estimates import result_row, rows_frame
from tfloc.io.maps import load_map
from tfloc.io.scenario import read_scans, read_scenario
from tfloc.io.table import frame_of
from tfloc.report.tracking import _cpu_ms, _own_odometry_rules, tracking_section


def _rows(name: str, n: int, lost_from: int | None = None) -> list:
    sc = read_scenario(ROOT / "data" / "scenarios" / name)
    scans = read_scans(sc)[:n]
    out = dead_reckoning(sc, scans, dataset=name)
    for k, s in enumerate(scans):  # a "perfect" matcher, lost (1 m off) from lost_from on
        est = s.true if lost_from is None or k < lost_from else s.true.compose(type(s.true)(1.0, 0.0, 0.0))
        out.append(result_row(name, "perfect", s.scan_id, s.group, true=s.true, init=s.true, est=est,
                              status="ok", wall_s=0.002, cpu_s=0.002, info={}))
    return out


def test_tables_and_figures(tmp_path):
    df = rows_frame(_rows("seq-rate-1hz-a", 40) + _rows("seq-rate-1hz-b", 40, lost_from=30) + _rows("seq-quick", 30))
    names = df["dataset"].unique()
    ds = {n: read_scenario(ROOT / "data" / "scenarios" / n) for n in names}
    s = frame_of(sequence_scores(df, {n: sc.extra for n, sc in ds.items()}), TrackingRow)
    assert set(s["condition"]) == {"rate-1hz", "quick"}
    rd = derive_tracking(tmp_path, df, ds)
    text = tracking_section(rd, df, ds, {n: load_map(ds[n].map_path) for n in names})
    assert "**rate-1hz** (2 sequences" in text and "**quick** (1 sequence" in text
    line = next(x for x in text.splitlines() if x.startswith("| perfect") and "[" in x)
    # pooled over the two sequences: 70 of 80 scans tracked, with a bootstrap interval
    assert line.split("|")[2].strip().startswith("87.5 [")
    assert "| 1 | 0 | 1 |" in line  # one loss, no recovery, unrecovered
    assert any(x.startswith("| odometry") for x in text.splitlines())
    figs = sorted(p.name for p in (tmp_path / "figures" / "tracking").iterdir())
    assert "seq-rate-1hz-b-trajectories.png" in figs and "seq-quick-error.png" in figs


def test_a_sequence_with_relations_gets_the_relation_errors_and_a_set_of_buildings_per_log_tables():
    from tfloc.io.scenario import read_scans, read_scenario
    from tfloc.report.tracking import relations_tables, tracking_tables

    root = SCEN
    rows, datasets = [], {}
    for name in ("real-csail-native", "real-aces-native"):
        sc = read_scenario(root / name)
        datasets[name] = sc
        for s in read_scans(sc)[:300]:
            pose = s.true if s.true is not None else s.odom     # truth where known
            rows.append(result_row(name, "perfect", s.scan_id, s.group, true=s.true, init=pose, est=pose,
                                   status="ok", wall_s=0.001, cpu_s=0.001, info={}))
    df = rows_frame(rows)
    text = relations_tables(df, datasets)
    assert "real-csail-native: relation errors" in text and "Cartographer (Hess et al. 2016" in text
    assert "real-aces-native: relation" not in text                      # no relations file named
    s = frame_of(sequence_scores(df, {n: sc.extra for n, sc in datasets.items()}), TrackingRow)
    t = tracking_tables(s, _cpu_ms(df), datasets)
    assert "**real-native: real-csail-native**" in t and "**real-native**" in t   # two buildings: per log too


def test_a_trackers_own_odometry_rule_is_stated_only_where_it_runs():
    base = _rows("seq-quick", 5)
    renamed = [dataclasses.replace(r, matcher="tf-plus-track-changed") for r in base if r.matcher == "perfect"]
    without = _own_odometry_rules(rows_frame(base))
    with_it = _own_odometry_rules(rows_frame(base + renamed))
    assert without == []
    assert len(with_it) == 1 and with_it[0].startswith("`tf-plus-track`'s own feature") and "no motion" in with_it[0]
