"""A fixed stratified sample of scans for the speed scripts: ``per`` scans of each dataset ×
group (first ``per`` in file order, so "before" and "after" checkouts see the same scans)."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAPER = ("office-pool", "detail-1", "detail-2", "detail-3")
REAL = ("real-intel-scan-to-map",)


def sample(datasets: tuple[str, ...], per: int, per_real: int) -> list[tuple[str, str, object]]:
    """``(dataset, scan_id, Problem)`` triples: ``per`` scans per group of the paper datasets,
    ``per_real`` scans (evenly spread) of each real dataset."""
    from tfloc.harness.task import load_dataset, problem_of

    out = []
    for name in datasets:
        scenario, scans = load_dataset(str(ROOT / "data" / "scenarios" / name))
        if name.startswith("real-"):
            items = list(scans.values())
            step = max(1, len(items) // per_real)
            chosen = items[::step][:per_real]
        else:
            groups: dict[str, list] = {}
            for s in scans.values():
                groups.setdefault(s.group, []).append(s)
            chosen = [s for g in sorted(groups) for s in groups[g][:per]]
        out += [(name, s.scan_id, problem_of(scenario, s)) for s in chosen]
    return out
