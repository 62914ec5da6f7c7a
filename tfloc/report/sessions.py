"""Which of a run.json's sessions made the rows a report shows."""

from __future__ import annotations


def this_run(sessions: list[dict]) -> list[dict]:
    """The sessions of the run the rows come from: from the last one that started with nothing
    done (``already_done`` 0; an older record's sessions before it ran other rows) to the end."""
    starts = [i for i, x in enumerate(sessions) if not x.get("already_done")]
    return sessions[starts[-1]:] if starts else sessions
