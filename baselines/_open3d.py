"""The one place that imports open3d.

open3d 0.20's wheel links against the system library ``libusb-1.0.so.0``, which a fresh
machine lacks. The ``libusb-package`` wheel ships that library; loading it with
``RTLD_GLOBAL`` before ``import open3d`` lets the dynamic linker resolve it.

open3d sizes its thread pool by the machine and ignores ``OMP_NUM_THREADS``; when the harness
has limited the process's threads (``TFLOC_THREADS``, :mod:`tfloc.harness.threads`), the same
limit is applied to open3d here, at import.
"""

from __future__ import annotations

import ctypes
import os
from functools import cache
from types import ModuleType


@cache
def import_open3d() -> ModuleType:
    """Preload libusb (if the system has none) and return the imported ``open3d`` module."""
    try:
        ctypes.CDLL("libusb-1.0.so.0", mode=ctypes.RTLD_GLOBAL)
    except OSError:
        import libusb_package

        path = libusb_package.get_library_path()
        if path is None:
            raise ImportError("libusb-package ships no libusb library for this platform") from None
        ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)
    import open3d

    if os.environ.get("TFLOC_THREADS", "").isdigit():
        open3d.utility.set_max_threads(int(os.environ["TFLOC_THREADS"]))
    return open3d
