from tfloc.core.run import Session
from tfloc.report.provenance import this_run


def test_a_report_counts_the_sessions_of_the_run_its_rows_come_from() -> None:
    old, fresh, resumed = Session("a", already_done=0), Session("b", already_done=0), Session("c", already_done=5)
    assert this_run((old, fresh, resumed)) == (fresh, resumed)
    assert this_run((old,)) == (old,) and this_run(()) == ()
    assert this_run((Session("x"), resumed)) == (Session("x"), resumed)  # no count: started fresh
