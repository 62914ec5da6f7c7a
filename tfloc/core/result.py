"""One result row: a (scan, matcher) task's answer, or one step of a tracked sequence.

:class:`ResultRow` is the one type every task, tracking loop, reader and writer passes around;
text exists only at the edge (``estimates.csv``: :mod:`tfloc.io.estimates`). Poses are split
into their ``_x``/``_y``/``_theta`` columns (metres, radians); a value the row does not have is
``None`` (an empty cell). ``status`` is a :class:`Status` (its kind and, for ``invalid`` and
``error``, the message), parsed from text in one place (:meth:`Status.parse`); ``info`` is the
matcher's extras as a dict (``None``: the task ended before a matcher answered).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from enum import StrEnum
from typing import Any


class StatusKind(StrEnum):
    """How a task ended: ``ok``; ``failed`` (the matcher declined or gave no finite pose);
    ``invalid`` (the data poses no problem: no matcher ran); ``timeout``; ``error`` (it raised)."""

    OK = "ok"
    FAILED = "failed"
    INVALID = "invalid"
    TIMEOUT = "timeout"
    ERROR = "error"


#: the kinds whose status carries a message (``invalid:<reason>``, ``error:<message>``)
WITH_MESSAGE = (StatusKind.INVALID, StatusKind.ERROR)
MESSAGE_CHARS = 300  # a message is cut to this length (one line)


@dataclass(frozen=True)
class Status:
    """A row's status: its kind and its message (``invalid`` and ``error`` only)."""

    kind: StatusKind = StatusKind.OK
    message: str = ""

    def __str__(self) -> str:
        return f"{self.kind.value}:{self.message}" if self.kind in WITH_MESSAGE else self.kind.value

    @classmethod
    def of(cls, kind: StatusKind | str, message: str = "") -> Status:
        """A status with its message made one line and cut to :data:`MESSAGE_CHARS`."""
        kind = StatusKind(kind)
        msg = message.replace("\n", " ").replace("\r", " ")
        return cls(kind, msg[:MESSAGE_CHARS - len(kind.value) - 1] if kind in WITH_MESSAGE else "")

    @classmethod
    def parse(cls, text: str) -> Status | None:
        """The status written as ``text`` (``ok``, ``failed``, ``timeout``, ``invalid:…``,
        ``error:…``), or ``None`` if it is none of them: the one parser of a status."""
        head, colon, message = str(text).partition(":")
        try:
            kind = StatusKind(head)
        except ValueError:
            return None
        if (kind in WITH_MESSAGE) != bool(colon):
            return None
        return cls(kind, message)

    @property
    def ok(self) -> bool:
        return self.kind is StatusKind.OK


OK = Status()


def kind_of_status(text: str) -> str | None:
    """The kind (``ok``, ``failed``, ``invalid``, ``timeout``, ``error``) of a status written as
    text, ``None`` for anything else."""
    s = Status.parse(text)
    return None if s is None else s.kind.value


@dataclass(frozen=True)
class ResultRow:
    """One row of ``estimates.csv`` (module notes). Errors are the estimate's against the truth
    (metres, radians); times in seconds (``runtime_s`` wall, ``cpu_s`` CPU); ``outcome`` is the
    one rule's (:mod:`tfloc.evaluation.outcome`), empty where it was not scored; ``score_*`` the
    matcher's own objective at its answer and at the truth, for a failure."""

    dataset: str
    scan_id: str
    group: str
    matcher: str
    true_x: float | None = None
    true_y: float | None = None
    true_theta: float | None = None
    init_x: float | None = None
    init_y: float | None = None
    init_theta: float | None = None
    est_x: float | None = None
    est_y: float | None = None
    est_theta: float | None = None
    dist_err_m: float | None = None
    orient_err_rad: float | None = None
    init_dist_err_m: float | None = None
    init_orient_err_rad: float | None = None
    runtime_s: float | None = None
    cpu_s: float | None = None
    converged: int | None = None
    iterations: int | None = None
    evaluations: int | None = None
    status: Status = OK
    outcome: str = ""
    score_est: float | None = None
    score_true: float | None = None
    info: dict | None = field(default=None, hash=False)

    @property
    def key(self) -> tuple[str, str, str]:
        """(dataset, scan_id, matcher): what identifies the row in a run."""
        return (self.dataset, self.scan_id, self.matcher)

    def with_(self, **changes: Any) -> ResultRow:
        """A copy with ``changes`` (a frozen row is never edited in place)."""
        return replace(self, **changes)


#: the columns of ``estimates.csv``, in order: the fields of :class:`ResultRow`
COLUMNS = [f.name for f in fields(ResultRow)]
