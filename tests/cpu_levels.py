"""``python tests/cpu_levels.py no-avx512|no-avx2``: the names to put in ``NPY_DISABLE_CPU_FEATURES``
so that numpy computes as it does on a CPU without AVX-512 (or without AVX2 and FMA as well),
taken from this numpy's own dispatch targets (numpy 2.4 names them ``X86_V3``/``X86_V4``, older
releases ``AVX2``, ``AVX512F``, ``AVX512_SKX``, …; a name numpy does not know is silently ignored,
so the list cannot be written down once). ``make test-cpu`` uses it, with the matching
``OPENBLAS_CORETYPE``; ``tests/toolchain/test_cpu_level.py`` checks that the pass got what it asked for.

``python tests/cpu_levels.py --native LEVEL`` exits 0 when this machine computes at ``LEVEL``
anyway: its CPU has none of the targets the level disables (numpy dispatches to the same code)
and OpenBLAS already runs the level's kernels. ``make test-cpu`` then skips the level: the plain
pass of ``make test`` is that pass already."""

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


def native(level: str) -> bool:
    """This machine computes at ``level`` without being told: none of the numpy targets the level
    disables is supported by its CPU (a name numpy does not list counts as supported), and every
    OpenBLAS loaded with numpy and scipy runs the level's kernels."""
    try:
        from numpy._core._multiarray_umath import __cpu_features__
    except ImportError:  # numpy < 2
        from numpy.core._multiarray_umath import __cpu_features__
    import scipy.linalg  # noqa: F401  (loads scipy's OpenBLAS too)
    from threadpoolctl import threadpool_info

    if any(__cpu_features__.get(t, True) for t in disabled(level)):
        return False
    blas = [i.get("architecture") for i in threadpool_info() if i.get("internal_api") == "openblas"]
    return bool(blas) and set(blas) == {OPENBLAS_CORETYPE[level]}


if __name__ == "__main__":
    args = sys.argv[1:]
    check = args[:1] == ["--native"]
    if len(args) != 1 + check or args[-1] not in PREFIXES:
        sys.exit(f"usage: python {sys.argv[0]} [--native] {'|'.join(PREFIXES)}")
    if check:
        sys.exit(0 if native(args[-1]) else 1)
    print(" ".join(disabled(args[-1])))
