"""The row types of a run directory's files: one frozen dataclass per file's row, its columns the
fields in order (:mod:`tfloc.io.table` is the one codec that writes and reads them,
:mod:`tfloc.io.tables` names each file's type). Percentages in %, errors in cm or degrees as
their names say, CPU in ms; a value not computed is NaN (an empty cell)."""
