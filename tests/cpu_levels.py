"""``python tests/cpu_levels.py no-avx512|no-avx2``: the names to put in ``NPY_DISABLE_CPU_FEATURES``
so that numpy computes as it does on a CPU without AVX-512 (or without AVX2 and FMA as well),
taken from this numpy's own dispatch targets (numpy 2.4 names them ``X86_V3``/``X86_V4``, older
releases ``AVX2``, ``AVX512F``, ``AVX512_SKX``, …; a name numpy does not know is silently ignored,
so the list cannot be written down once). ``make test-cpu`` uses it, with the matching
``OPENBLAS_CORETYPE``; ``tests/toolchain/test_cpu_level.py`` checks that the pass got what it asked for."""

from __future__ import annotations

import sys

PREFIXES = {"no-avx512": ("AVX512", "X86_V4"),
            "no-avx2": ("AVX512", "X86_V4", "X86_V3", "AVX2", "FMA3")}
OPENBLAS_CORETYPE = {"no-avx512": "Haswell", "no-avx2": "Sandybridge"}


def dispatch_targets() -> list[str]:
    """numpy's runtime-dispatched CPU targets (compiled in; the machine may lack some)."""
    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__
    except ImportError:  # numpy < 2
        from numpy.core._multiarray_umath import __cpu_dispatch__
    return list(__cpu_dispatch__)


def disabled(level: str) -> list[str]:
    """The dispatch targets at or above ``level``'s first missing extension."""
    return [t for t in dispatch_targets() if t.startswith(PREFIXES[level])]


if __name__ == "__main__":
    if len(sys.argv) != 2 or sys.argv[1] not in PREFIXES:
        sys.exit(f"usage: python {sys.argv[0]} {'|'.join(PREFIXES)}")
    print(" ".join(disabled(sys.argv[1])))
