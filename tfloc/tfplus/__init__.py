"""``tf-plus``, the project's own turning-function localizer, one module per stage: heading seeds
(``headings``), the coarse grid (``coarse``), point-to-line refinement (``refine``), the selection
cost (``cost``), each stage's compiled kernels (``*_kernel``), the one-call pipeline
(``pipeline``) and the matcher (``matcher``)."""
