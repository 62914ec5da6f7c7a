"""``make test-cpu`` reruns the ``bitwise`` tests as a CPU without AVX-512 (then without AVX2)
would compute; these checks make sure such a pass really computed that way (numpy ignores a
feature name it does not know, so a stale name would make the pass a silent copy of the first)."""

from __future__ import annotations

import os

import pytest
from cpu_levels import OPENBLAS_CORETYPE, PREFIXES, disabled, native

LEVEL = os.environ.get("TFLOC_CPU_LEVEL")
pytestmark = pytest.mark.bitwise


@pytest.mark.skipif(LEVEL is None, reason="not a make test-cpu pass")
def test_numpy_dispatches_below_the_level_of_the_pass() -> None:
    from numpy.lib.introspect import opt_func_info

    assert LEVEL in PREFIXES, LEVEL
    current = {sig["current"] for f in opt_func_info(func_name="^(sin|cos|exp|arctan2)$").values()
               for sig in f.values()}
    assert not any(c.startswith(PREFIXES[LEVEL]) for c in current), current
    assert os.environ.get("NPY_DISABLE_CPU_FEATURES", "").split() == disabled(LEVEL)


@pytest.mark.skipif(LEVEL is None, reason="not a make test-cpu pass")
def test_openblas_runs_the_kernels_of_the_level() -> None:
    import numpy  # noqa: F401  (loads numpy's OpenBLAS)
    import scipy.linalg  # noqa: F401  (and scipy's, which numba's np.linalg calls)
    from threadpoolctl import threadpool_info

    blas = [i for i in threadpool_info() if i.get("internal_api") == "openblas"]
    assert blas and {i["architecture"] for i in blas} == {OPENBLAS_CORETYPE[LEVEL]}, blas


def test_the_levels_name_targets_of_this_numpy() -> None:
    """Each level disables at least one of this numpy's dispatch targets (on x86-64)."""
    import platform

    if platform.machine() not in ("x86_64", "AMD64"):
        pytest.skip("x86-64 levels")
    assert disabled("no-avx512") and set(disabled("no-avx512")) < set(disabled("no-avx2"))


@pytest.mark.skipif(LEVEL is not None, reason="asks about the machine, not about a pass")
def test_a_level_is_skipped_only_where_the_cpu_lacks_what_it_disables() -> None:
    """``make test-cpu`` skips a level this CPU computes at anyway; never one whose targets it has."""
    try:
        from numpy._core._multiarray_umath import __cpu_features__
    except ImportError:  # numpy < 2
        from numpy.core._multiarray_umath import __cpu_features__

    for level in PREFIXES:
        if any(__cpu_features__.get(t, True) for t in disabled(level)):
            assert not native(level), level
    if __cpu_features__.get("AVX2"):
        assert not native("no-avx2")
