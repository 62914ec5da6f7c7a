"""Execution: run configurations (``config``), one task per (scan, matcher) (``task``), the local
process pool with time limits and resume (``runner``) and the Dask executor (``dask_*``)."""
