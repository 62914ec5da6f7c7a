"""A dataset's kind: a real recording or a simulated stand-in, read from its ``scenario.json``,
never from its name. An explicit ``"kind"`` (``real`` or ``simulated``) decides; without one, a
dataset is real when it records the recording it was made from (``"source": {"files": [...]}``,
as ``tfloc real-data`` writes for the scans of a log) and simulated otherwise (``tfloc
generate``'s offices, and the scans ``tfloc real-data`` ray-casts in a real map, which name no
source files)."""

from __future__ import annotations

REAL, SIMULATED = "real", "simulated"
KINDS = (REAL, SIMULATED)


def dataset_kind(scenario: dict) -> str:
    """``real`` or ``simulated`` for the fields of a ``scenario.json`` (the whole document or
    :attr:`tfloc.io.scenario.Scenario.extra`)."""
    kind = scenario.get("kind")
    if kind in KINDS:
        return str(kind)
    source = scenario.get("source")
    return REAL if isinstance(source, dict) and source.get("files") else SIMULATED
