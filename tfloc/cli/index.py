"""Build (or load) tf-global's place index of a dataset's map, before a run.

The index depends only on the map, the laser and tf-global's index parameters; it is stored
under the map's content hash (``$TFLOC_INDEX_CACHE``, else ``~/.cache/tfloc/index``, or
``--param cache_dir=...``), so a benchmark's workers load it (a fraction of a second) instead of
each building it (seconds to a minute on a large map) inside a task's time limit. Prints the
index's entries, the map's free area, the build CPU time, the size in memory and on disk.

Example:
  tfloc index --dataset data/scenarios/real-intel-scan-to-map
  tfloc index --dataset DIR --param index.step=0.5 --param cache_dir=/tmp/idx
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from tfloc.core.matcher import get_matcher
from tfloc.core.problem import Problem
from tfloc.errors import ConfigError, DatasetError, ParameterError
from tfloc.harness.threads import limit_threads
from tfloc.io.scenario import iter_scans, map_for, read_scenario
from tfloc.relocalize.index import default_cache_dir

from ._matcher import parse_params

HELP = "build or load tf-global's place index of a dataset's map (before a run)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dataset", required=True, type=Path, help="scenario dataset directory")
    p.add_argument("--matcher", default="tf-global", help="a matcher with a place index "
                   "(default: tf-global)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="a matcher parameter, VALUE in TOML syntax (repeatable)")


def run(args: argparse.Namespace) -> int:
    return index(args.dataset, args.matcher, args.param)


def index(dataset: Path, matcher_name: str = "tf-global", params: list[str] = ()) -> int:
    """Build or load the place index of ``dataset``'s map (``params``: ``KEY=VALUE`` texts; the
    study step ``index`` calls it)."""
    limit_threads(1)
    try:  # a fresh matcher (not the workspace's cached one), so a second call loads from disk
        matcher = get_matcher(matcher_name, **parse_params(list(params)))
    except ParameterError as exc:
        key = f"--param {exc.names[0]}" if exc.names else f"--matcher {matcher_name}"
        raise ConfigError(f"{key}: {exc}") from None
    if not callable(getattr(matcher, "index", None)):
        raise ConfigError(f"--matcher {matcher_name}: it keeps no place index")
    scenario = read_scenario(dataset)
    scan = next(iter_scans(scenario), None)
    if scan is None:
        raise DatasetError(f"{scenario.scans_path}: no scans")
    # the map loaded afresh (not the workspace's per-process copy): the index is then loaded from
    # disk, not found in memory, and the command says so
    problem = Problem(map_for(scenario, scan, {}), scenario.laser, scan.ranges, None,
                      where=f"{scenario.scans_path}:{scan.line}")
    c0 = time.process_time()
    idx = matcher.index(problem)
    cpu = time.process_time() - c0
    cache = Path(matcher.config.cache_dir) if matcher.config.cache_dir else default_cache_dir()
    path = cache / f"{idx.key}.npz"
    disk = f"{path.stat().st_size / 2**20:.1f} MiB" if path.exists() else "not stored"
    how = f"loaded in {cpu:.2f} s CPU" if idx.loaded else "built"
    print(f"{scenario.name}: {len(idx.poses)} entries over {idx.free_area_m2:.0f} m² free, "
          f"{how} (build {idx.build_cpu_s:.1f} s CPU), {idx.nbytes / 2**20:.1f} MiB in memory, "
          f"{path} ({disk})")
    return 0
