"""``tf-plus``, the project's own turning-function localizer, one module per stage: heading seeds
(``headings``), the coarse grid (``coarse``), point-to-line refinement (``refine``), the selection
cost (``cost``), their compiled kernels (``kernels``) and the matcher (``matcher``)."""
