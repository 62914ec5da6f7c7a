"""``python tests/warm_kernels.py``: compile tfloc's kernels into numba's on-disk cache before
``make test`` starts its two test processes (a fresh clone has no cache).

Left to the tests, a kernel is compiled by whichever test calls it first: often by both test
processes at once, and again by every process of a command a test runs (``tfloc bench`` and its
pool workers) while the cache is still empty; tf-plus's pipelines alone take a minute each time.
Here every registered matcher and preset localizes (a tracker: starts and steps) one scan of the
test room, on the vector map and on a 5 cm grid, in two processes: the tf-plus family (whose
kernels ``tf-global`` runs too) in one, the others in the other, so each kernel is compiled once.
With the cache warm it only loads them (seconds). It never fails ``make test``: a matcher that
raises here is reported and left to its tests.
"""

from __future__ import annotations

import sys
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

ROOM = Path(__file__).resolve().parents[1] / "data" / "maps" / "test-room.geojson"


def _names() -> tuple[list[str], list[str]]:
    """Registered matchers and presets: the tf-plus family and tf-global, then the others."""
    from tfloc.core.matcher import available_matchers
    from tfloc.core.presets import presets

    names = [*available_matchers(), *presets()]
    family = [n for n in names if n.startswith("tf-plus") or n == "tf-global"]
    return family, [n for n in names if n not in family]


def warm(half: int) -> list[str]:
    """Run each matcher of one half of :func:`_names` once on both maps; returns one line per
    matcher that raised."""
    import numpy as np

    import tfloc
    from tfloc.core.external import is_batch_tracker
    from tfloc.core.pose import Pose
    from tfloc.maps.build import rasterize

    room = tfloc.load_map(ROOM)
    laser = tfloc.LaserSpec.lms200()
    truth = Pose(3.1, 2.4, 0.3)
    ranges = room.raycast(truth, laser)
    guess = Pose(truth.x + 0.12, truth.y - 0.09, truth.theta + float(np.radians(3.0)))
    maps = (room, rasterize(room, 0.05))
    failed = []
    for name in _names()[half]:
        for map_ in maps:
            try:
                m = tfloc.get_matcher(name)
                if is_batch_tracker(m):  # an external program: no in-process kernel to warm
                    continue
                if hasattr(m, "localize"):
                    m.localize(tfloc.Problem(map_, laser, ranges, guess))
                else:  # a tracker: started at the guess, one scan
                    m.start(map_, laser, guess)
                    m.step(ranges, Pose(0.0, 0.0, 0.0), 0.0)
            except Exception as exc:  # noqa: BLE001 - its own tests report it properly
                failed.append(f"{name} on {type(map_).__name__}: {type(exc).__name__}: {exc}"[:200])
    return failed


def main() -> int:
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2, mp_context=get_context("spawn")) as pool:
        failed = [line for lines in pool.map(warm, (0, 1)) for line in lines]
    for line in failed:
        print(f"warm_kernels: {line}", file=sys.stderr)
    print(f"warm_kernels: tfloc's kernels compiled or loaded in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
