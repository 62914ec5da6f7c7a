"""What a run shows: ``report.md`` (``report``, ``sections``, ``mdtable``), its figures
(``figures``), the MIT CSAIL relations note (``relations_note``) and TUM export (``export``)."""
