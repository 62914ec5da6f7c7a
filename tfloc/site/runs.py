"""The site's one way into a run directory's ``run.json`` and its datasets: through
:class:`tfloc.io.rundir.RunDir` (which reads and checks ``run.json``), never a raw JSON read. A
run whose ``run.json`` is missing or malformed reads as an empty record (its page says
"unknown" rather than the site failing); a dataset's ``scenario.json`` is read by
:func:`tfloc.io.scenario.read_scenario` from the directory the run recorded, else from
``data/scenarios/<name>``."""

from __future__ import annotations

from pathlib import Path

from tfloc.core.run import RunRecord
from tfloc.errors import TflocError
from tfloc.io.rundir import RunDir
from tfloc.io.scenario import read_scenario

from .kinds import dataset_kind

#: where a dataset the run did not record (or recorded elsewhere) is looked for
SCENARIOS = Path("data/scenarios")


def run_info(run_dir: Path) -> RunRecord:
    """The run's checked ``run.json`` (an empty :class:`~tfloc.core.run.RunRecord` when it has none
    or it is malformed)."""
    try:
        return RunDir(run_dir).info()
    except TflocError:
        return RunRecord()


def dataset_kinds(info: RunRecord, names: list[str], base: Path | None = None) -> dict[str, str]:
    """Dataset name → ``real`` or ``simulated`` (:func:`tfloc.site.kinds.dataset_kind`) for the
    ``names`` whose ``scenario.json`` is readable; the others are left out (kind unknown). A
    relative directory is tried as it is (from where the verb runs) and, with ``base`` (the
    results root's parent: the checkout the run was made in), under ``base``."""
    recorded = info.paths
    out = {}
    for name in dict.fromkeys(names):
        places = [p for p in (recorded.get(name), SCENARIOS / name) if p is not None]
        places += [base / p for p in places if base is not None and not p.is_absolute()]
        for where in places:
            try:
                out[name] = dataset_kind(read_scenario(where).extra)
                break
            except TflocError:
                continue
    return out
