"""Scoring, pure functions over a run's estimates: the success/outcome rule (``outcome``), metrics
and summaries (``metrics``, ``summary``), the paper's published values (``paper``), relation errors
(``relations``) and the regression guard's rules (``guard``)."""
