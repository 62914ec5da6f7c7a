# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Nav2's particle filter, ``nav2_amcl/src/pf/``: ``pf.c``, ``pf_kdtree.c``, ``pf_pdf.c``, ``eig3.c``."""
