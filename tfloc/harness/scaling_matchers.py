"""Which matchers a scaling study runs, and what decides its rows (its fingerprint).

:func:`study_matchers` builds the named matchers (default: every registered single-scan local
matcher); :func:`study_fingerprint` is the tile map's content hash, every matcher with its resolved
parameters and the code that decides its rows (:func:`tfloc.harness.preflight.matcher_record`
with the study's own row code, :data:`ROW_CODE`), the
success thresholds and the study's configuration (:class:`~tfloc.harness.scaling_config.StudyConfig`,
all of it). :func:`study_differences` says what differs from a recorded one, one phrase each:
:func:`tfloc.harness.fingerprint.differences` for the code, map and matchers, then the
configuration's fields (``scans_per_level 2 → 3``).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from tfloc.core.jsonable import jsonable
from tfloc.core.matcher import Matcher, available_matchers, get_matcher, solves_global
from tfloc.core.tracker import has_single_scan_mode
from tfloc.errors import ConfigError, LibraryMissingError, ResultsError

from .config import MatcherSpec
from .fingerprint import code_files, differences
from .identity import tfloc_version
from .preflight import matcher_record
from .scaling_config import THRESHOLDS, Log, StudyConfig

#: the study's code that turns a matcher's answers into rows: a level's measurement (tiling, timing,
#: scoring) and the rows' codec
ROW_CODE = ("tfloc.harness.scaling_level", "tfloc.io.table")


def study_matchers(names: Sequence[str] | None, log: Log) -> dict[str, Matcher]:
    """Every named matcher with its defaults, built by :func:`tfloc.core.matcher.get_matcher`
    (default: every registered single-scan local matcher); one whose library is missing is left
    out with one line to ``log``.

    By default a tracker without a single-scan mode (amcl, tf-plus-recover), ``odometry`` (no
    objective: it answers its guess at no cost) and a global matcher (tf-global, bnb-global) are
    left out, each with one line: the study's problems are local ones, and a global matcher's cost
    against the area is its own axis (``results/global``). Named, they run (a global matcher then
    answers the local problem its own way; a tracker without a single-scan mode cannot)."""
    chosen = names is not None
    out: dict[str, Matcher] = {}
    for name in names if chosen else available_matchers():
        if ":" in name:
            raise ConfigError(f"matcher {name!r}: the scaling study runs registered matchers only")
        try:
            m = get_matcher(name)
        except LibraryMissingError as exc:
            log(f"left out: {exc}")
            continue
        why = ("no single-scan mode" if not has_single_scan_mode(m) else "" if chosen
               else "a global matcher" if solves_global(m)
               else "no objective: it answers its guess" if not hasattr(m, "score") else "")
        if why:
            log(f"left out: {name} ({why})")
            continue
        out[name] = m
    if not out:
        raise ConfigError("scaling study: no matcher to run")
    return out


def _sha256(path: Path) -> str:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError as exc:
        raise ResultsError(f"{path}: cannot read the tile map ({exc.strerror or exc})") from None


def study_fingerprint(cfg: StudyConfig, matchers: Sequence[str]) -> dict[str, Any]:
    """What decides the study's rows (module notes); JSON-normalised. ``scaling`` holds the
    configuration's fields."""
    path = Path(cfg.map_path)
    records = {n: matcher_record(MatcherSpec.make(n), ROW_CODE) for n in matchers}
    fp = {"tfloc": {"version": tfloc_version(), "files": code_files(records, ROW_CODE)},
          "datasets": {"map": {path.name: _sha256(path)}}, "matchers": records,
          "success": THRESHOLDS.to_dict(), "scaling": asdict(cfg)}
    return jsonable(fp)


def study_differences(old: dict | None, new: dict) -> list[str]:
    """What differs between a recorded study fingerprint and a new one, one phrase each (module
    notes); empty when they are the same."""
    if not isinstance(old, dict):
        return ["it records no fingerprint (made by an older tfloc: study.json, or run.json is missing)"]
    a = old.get("scaling") if isinstance(old.get("scaling"), dict) else {}
    return differences(old, new) + [f"{k} {json.dumps(a.get(k))} → {json.dumps(v)}"
                                    for k, v in new["scaling"].items() if a.get(k) != v]
