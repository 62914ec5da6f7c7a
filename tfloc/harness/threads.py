"""One thread per matcher: the thread limits of a worker process, set and read back.

Runtimes are CPU time of the worker process (all its threads), so a matcher that spread over
several threads would be charged for all of them, and two workers on two cores would compete.
Every library with a thread pool is therefore limited to ``n`` threads (1 in the harness):

* BLAS and OpenMP runtimes already loaded: ``threadpoolctl.threadpool_limits``; those loaded
  later read ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS``, ... (set here first).
* numba: ``NUMBA_NUM_THREADS``, read into numba's configuration again
  (``numba.core.config.reload_config``: numba was imported before any initializer runs). Its
  thread pool is not launched here: numba refuses a configuration that differs from a launched
  pool's size when it next compiles. (tfloc's kernels are not parallel; this bounds any that are.)
* OpenCV: ``cv2.setNumThreads`` (it ignores the variables above).
* open3d: ``open3d.utility.set_max_threads``. open3d ignores ``OMP_NUM_THREADS`` (measured:
  ``get_max_threads()`` is 2 on 2 cores with ``OMP_NUM_THREADS=1``), so the limit is applied
  when open3d is imported (:func:`tfloc.baselines._open3d.import_open3d` reads
  ``TFLOC_THREADS``) or here when it already is.
* kiss-icp: its TBB pool is sized per ``Registration`` (``max_num_threads``; the ``kiss-icp``
  matcher passes 1).

:func:`thread_settings` reads every limit back; ``tests/toolchain/test_threads.py`` checks them in a
worker and that a busy matcher's CPU time does not exceed its wall time.
"""

from __future__ import annotations

import os
import sys

THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS",
               "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS", "TFLOC_THREADS")


def limit_threads(n: int = 1) -> None:
    """Limit every thread pool of this process (present and future) to ``n`` threads."""
    for var in THREAD_VARS:
        os.environ[var] = str(n)
    import cv2
    import numba.core.config

    cv2.setNumThreads(n)
    numba.core.config.reload_config()
    if "open3d" in sys.modules:
        sys.modules["open3d"].utility.set_max_threads(n)
    try:  # last: the runtimes loaded above are limited too
        from threadpoolctl import threadpool_limits

        threadpool_limits(n)
    except ImportError:
        pass


def thread_settings() -> dict[str, int]:
    """The thread limit of every pool this process has loaded, by library (for tests and run.json)."""
    import cv2
    import numba.core.config

    out = {"cv2": int(cv2.getNumThreads()), "numba": int(numba.core.config.NUMBA_NUM_THREADS)}
    if "open3d" in sys.modules:
        out["open3d"] = int(sys.modules["open3d"].utility.get_max_threads())
    try:
        from threadpoolctl import threadpool_info

        for info in threadpool_info():
            key = f"{info['internal_api']}:{os.path.basename(info['filepath'])}"
            out[key] = int(info["num_threads"])
    except ImportError:
        pass
    return out
