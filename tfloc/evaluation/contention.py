"""Whether a timing pass ran on a contended machine: the contention probe's figures and verdict.

The two cores of the machine are not independent: a busy neighbour (another process on the other
core, or time-sliced on the same one) slows even the CPU time of a pinned process, through the
shared caches and memory bandwidth. The timing pass therefore times a fixed calibration workload
(:mod:`tfloc.harness.contention`) once per round, interleaved with the matchers, after a short
reference at the start, and reads the machine's busy time from ``/proc/stat`` over the pass.

:class:`Contention` holds what was measured: the calibration's CPU times (ms; the quiet
reference's minimum, the minimum over reference and rounds, the median over the rounds), the
neighbours' CPU share (cores: the machine's busy time minus this process's own, over the wall time)
and the hypervisor's stolen share (cores), and the load average. Its inflation is
``median / minimum``: how much slower the workload ran in a typical round than at its best.

A pass is **contended** when its inflation exceeds :data:`MAX_INFLATION` or its neighbours used more
than :data:`MAX_NEIGHBOUR_CORES` of a core. Why these values (docs/speed.md, how measured): on the
quiet machine a pass's calibration ran ×1.12 its minimum (the matchers evict its table between
rounds) and the neighbours used 0.00 core; beside a memory-bandwidth hog on the other core the
probe ran ×1.93, and a CPU hog showed as 0.6–1.0 neighbour core while moving the calibration
only ×1.16–1.26. ×1.25 and 0.25 core sit between. Either signal alone can miss: a hog that shares
no cache moves the calibration little; a pass contended throughout raises its minimum too.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields

import numpy as np

#: the calibration's median over its minimum above which a pass is contended
MAX_INFLATION = 1.25
#: the neighbours' CPU share (cores) above which a pass is contended
MAX_NEIGHBOUR_CORES = 0.25
NOT_MEASURED = "contention not measured (made before the contention probe)"
#: the keys of :attr:`Contention.loadavg` (start, end) in a ``run.json`` record
LOADAVG_KEYS = ("loadavg_start", "loadavg_end")


@dataclass(frozen=True)
class Contention:
    """The contention probe's figures for one pass (module notes): calibration CPU ms (quiet
    reference minimum, minimum of all, median of the rounds), the number of rounds, the
    neighbours' and the stolen CPU share (cores; NaN where ``/proc/stat`` is unreadable) and the
    1-minute load average at the start and the end (NaN if unknown)."""

    calib_quiet_ms: float
    calib_min_ms: float
    calib_median_ms: float
    rounds: int
    neighbour_cores: float
    steal_cores: float = math.nan
    loadavg: tuple[float, float] = (math.nan, math.nan)
    thresholds: dict = field(default_factory=lambda: {"inflation": MAX_INFLATION,
                                                      "neighbour_cores": MAX_NEIGHBOUR_CORES})

    @property
    def inflation(self) -> float:
        """The calibration's median CPU time over its minimum (≥ 1; NaN without rounds)."""
        if not self.calib_min_ms > 0 or math.isnan(self.calib_median_ms):
            return math.nan
        return self.calib_median_ms / self.calib_min_ms

    def reasons(self) -> list[str]:
        """Why the pass is contended, one phrase per signal over its threshold (empty: quiet)."""
        out = []
        if self.inflation > self.thresholds.get("inflation", MAX_INFLATION):
            out.append(f"calibration ×{self.inflation:.2f} its minimum")
        if self.neighbour_cores > self.thresholds.get("neighbour_cores", MAX_NEIGHBOUR_CORES):
            out.append(f"neighbours used {self.neighbour_cores:.2f} core")
        return out

    @property
    def contended(self) -> bool:
        return bool(self.reasons())

    def to_record(self) -> dict:
        """The figures for ``run.json`` (NaN as None; the load average as ``loadavg_start`` and
        ``loadavg_end``), the inflation and the verdict beside them."""
        d = {}
        for k, v in asdict(self).items():
            if k == "loadavg":
                d.update(zip(LOADAVG_KEYS, v, strict=True))
            else:
                d[k] = v
        d = {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in d.items()}
        inf = self.inflation
        return {**d, "inflation": None if math.isnan(inf) else round(inf, 4), "contended": self.contended}

    @classmethod
    def from_record(cls, record: object) -> Contention | None:
        """The figures a ``run.json`` records, None where it records none (an older pass) or they
        are malformed."""
        if not isinstance(record, dict):
            return None
        kw = {}
        for f in fields(cls):
            v = record.get(f.name)
            if f.name == "thresholds":
                if isinstance(v, dict):
                    kw[f.name] = v
            elif f.name == "rounds":
                kw[f.name] = int(v) if isinstance(v, (int, float)) else 0
            elif f.name == "loadavg":
                kw[f.name] = tuple(_number(record.get(k)) for k in LOADAVG_KEYS)
            else:
                kw[f.name] = _number(v)
        return cls(**kw)


def assess(reference_ms: list[float], rounds_ms: list[float], busy_s: float, own_s: float, wall_s: float,
           steal_s: float = math.nan, loadavg: tuple[float, float] = (math.nan, math.nan)) -> Contention:
    """The figures of a pass from its readings: the calibration's CPU ms at the start
    (``reference_ms``) and in each round (``rounds_ms``); the machine's busy and stolen CPU seconds
    (all cores, ``/proc/stat``), this process's own CPU seconds and the wall seconds, each over the
    pass (NaN: not read). The neighbours' share is ``(busy − own) / wall`` cores, at least 0."""
    ref = [v for v in reference_ms if v > 0]
    rounds = [v for v in rounds_ms if v > 0]
    every = ref + rounds
    neighbours = (busy_s - own_s) / wall_s if wall_s > 0 else math.nan
    neighbours = neighbours if math.isnan(neighbours) else max(0.0, neighbours)  # max() keeps 0 over NaN
    return Contention(
        calib_quiet_ms=float(min(ref)) if ref else math.nan,
        calib_min_ms=float(min(every)) if every else math.nan,
        calib_median_ms=float(np.median(rounds)) if rounds else math.nan,
        rounds=len(rounds), neighbour_cores=neighbours,
        steal_cores=max(0.0, steal_s / wall_s) if wall_s > 0 and not math.isnan(steal_s) else math.nan,
        loadavg=(loadavg[0], loadavg[1]))


def _number(v: object) -> float:
    """A recorded figure as a float, NaN where it is missing or not a number."""
    return float(v) if isinstance(v, (int, float)) else math.nan


def mark(c: Contention | None) -> str:
    """A pass's mark for tables: ``contended (×1.42 inflated)``, empty when quiet or not measured."""
    if c is None or not c.contended:
        return ""
    return f"contended (×{c.inflation:.2f} inflated)" if not math.isnan(c.inflation) else "contended"


def describe(c: Contention | None) -> str:
    """One sentence on a pass's contention (for ``timing.md`` and the command line)."""
    if c is None:
        return NOT_MEASURED
    nb = "not read" if math.isnan(c.neighbour_cores) else f"{c.neighbour_cores:.2f} core"
    figures = (f"calibration median {c.calib_median_ms:.2f} ms over its minimum {c.calib_min_ms:.2f} ms "
               f"(×{c.inflation:.2f}, {c.rounds} rounds; quiet reference {c.calib_quiet_ms:.2f} ms), "
               f"neighbours' CPU {nb}" + ("" if math.isnan(c.steal_cores) else f", stolen {c.steal_cores:.2f} core"))
    limits = f"limits ×{c.thresholds.get('inflation', MAX_INFLATION):g} and " \
             f"{c.thresholds.get('neighbour_cores', MAX_NEIGHBOUR_CORES):g} core"
    if c.contended:
        return f"CONTENDED ({'; '.join(c.reasons())}): {figures}; {limits}"
    return f"quiet: {figures}; {limits}"
