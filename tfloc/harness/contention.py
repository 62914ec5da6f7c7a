"""The contention probe: a fixed calibration workload timed beside the matchers, and the machine's
busy time over a pass (the verdict's rules: :mod:`tfloc.evaluation.contention`).

The workload (:func:`calibrate`, ≈5 ms) gathers a fixed pseudo-random permutation of a 1 MB
float32 table (a core's L2 here; a 4 MB table varied ×1.16–1.19 median / minimum on the quiet
machine, this one ×1.03) and sums it, 14 times: memory- and
cache-bound like the matchers' look-ups in distance fields and lattices, deterministic, no
allocation beyond its output. :class:`Probe` times it :data:`REFERENCE` times at the start of a
pass (the quiet reference) and once per round (a round: one scan or step, every matcher once),
and reads ``/proc/stat`` (the machine's busy and stolen jiffies, all cores) and ``os.times``
(this process's own user + system time, with its waited-for children's) at the start and the end. A child the pass does
not wait for counts as a neighbour.

``python -m tfloc.harness.contention [SECONDS] [--core N]`` runs the probe alone, pinned, for
SECONDS and prints its figures: how docs/speed.md measured quiet and beside a hog.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from functools import cache

import numpy as np

from tfloc.evaluation.contention import Contention, assess

from .runner import load_average

TABLE = 1 << 18       # float32 entries: 1 MB (a core's L2 here)
GATHER = 1 << 18      # look-ups per gather (a permutation of the table)
REPEAT = 14           # gathers per call: ≈5 ms
REFERENCE = 15        # calibration calls of the quiet reference at the start of a pass


@cache
def _workload() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(7)
    table = rng.random(TABLE, dtype=np.float32)
    index = rng.permutation(TABLE)[:GATHER].astype(np.intp)
    return table, index, np.empty(GATHER, dtype=np.float32)


def calibrate() -> float:
    """Run the calibration workload once; its CPU time (ms)."""
    table, index, out = _workload()
    t0 = time.process_time()
    for _ in range(REPEAT):
        np.take(table, index, out=out)
        out.sum()
    return 1000.0 * (time.process_time() - t0)


@dataclass(frozen=True)
class Reading:
    """A reading of the machine: wall seconds, the machine's busy and stolen CPU seconds (all
    cores; NaN where ``/proc/stat`` is unreadable) and this process's own CPU seconds."""

    wall_s: float
    busy_s: float
    steal_s: float
    own_s: float


def parse_proc_stat(text: str, ticks: int) -> tuple[float, float]:
    """The busy (user, nice, system, irq, softirq) and stolen CPU seconds of ``/proc/stat``'s
    ``cpu`` line (all cores; ``ticks`` jiffies per second)."""
    for line in text.splitlines():
        if line.startswith("cpu "):
            v = [int(x) for x in line.split()[1:]]
            v += [0] * (8 - len(v))
            return (v[0] + v[1] + v[2] + v[5] + v[6]) / ticks, v[7] / ticks
    raise ValueError("no cpu line")


def read() -> Reading:
    """The machine now (:class:`Reading`)."""
    t = os.times()
    try:
        with open("/proc/stat") as fh:
            busy, steal = parse_proc_stat(fh.read(), os.sysconf("SC_CLK_TCK"))
    except (OSError, ValueError):
        busy = steal = math.nan
    return Reading(time.perf_counter(), busy, steal, t.user + t.system + t.children_user + t.children_system)


class Probe:
    """The probe of one pass: :meth:`start` (the quiet reference and the first reading), then
    :meth:`round` once per round, then :meth:`finish` (the pass's :class:`Contention`)."""

    def __init__(self) -> None:
        self.reference: list[float] = []
        self.rounds: list[float] = []
        self.first: Reading | None = None
        self.load_start = math.nan

    def start(self) -> None:
        calibrate()  # untimed: the table into memory, numpy's paths warm
        self.load_start = (load_average() or [math.nan])[0]
        self.first = read()
        self.reference = [calibrate() for _ in range(REFERENCE)]

    def round(self) -> None:
        self.rounds.append(calibrate())

    def finish(self) -> Contention:
        if self.first is None:
            raise RuntimeError("Probe.finish before Probe.start")
        last, first = read(), self.first
        return assess(self.reference, self.rounds, last.busy_s - first.busy_s, last.own_s - first.own_s,
                      last.wall_s - first.wall_s, last.steal_s - first.steal_s,
                      (self.load_start, (load_average() or [math.nan])[0]))


def probe_alone(seconds: float) -> Contention:
    """The probe alone for ``seconds``: the reference, then rounds with 5 ms sleeps between them
    (a matcher's share of a round is left idle)."""
    p = Probe()
    p.start()
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        p.round()
        time.sleep(0.005)
    return p.finish()


if __name__ == "__main__":
    import argparse

    from tfloc.evaluation.contention import describe

    from .pinning import pinned

    ap = argparse.ArgumentParser(description="the contention probe alone, pinned (docs/speed.md)")
    ap.add_argument("seconds", type=float, nargs="?", default=10.0)
    ap.add_argument("--core", type=int, default=None, help="core to pin to (default: the last allowed)")
    a = ap.parse_args()
    with pinned(None if a.core is None else [a.core]) as on:
        c = probe_alone(a.seconds)
    print(f"core(s) {on}: {describe(c)}; load {c.loadavg[0]:.2f} → {c.loadavg[1]:.2f}")
