"""The project's folders, one copy for every test: the repository, its data, scenarios, maps and
real logs, its study files and committed results."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "data"
SCEN = DATA / "scenarios"
MAPS = DATA / "maps"
REAL = DATA / "real"
BENCHMARKS = ROOT / "benchmarks"
RESULTS = ROOT / "results"
