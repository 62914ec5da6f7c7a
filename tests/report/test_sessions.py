"""A report counts the sessions of the run its rows come from, not an older record's."""

from tfloc.report.sessions import this_run


def test_sessions_from_the_last_start_from_nothing():
    old, fresh, resumed = {"already_done": 0, "started": "a"}, {"already_done": 0, "started": "b"}, {"already_done": 5}
    assert this_run([old, fresh, resumed]) == [fresh, resumed]
    assert this_run([old]) == [old] and this_run([]) == []
    assert this_run([{"started": "x"}, resumed]) == [{"started": "x"}, resumed]  # no count recorded: a start
