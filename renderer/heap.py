"""Keep freed memory in the process's heap, so a render's temporaries are reused.

A tile of a 256^2 frame allocates and frees a few hundred numpy temporaries of
50 to 520 KB each.  With glibc's default settings the freed memory at the top of
the heap is handed back to the kernel as soon as more than a few times the
largest freed block lies free there (``M_TRIM_THRESHOLD``), and blocks above
the mmap threshold are mapped and unmapped on every allocation.  Either way
the next tile's temporaries are fresh pages, and each page costs a page fault
when first written: about 7,400 minor faults per 256^2 frame on one thread
here, a third of its run time (benchmarks/results/render.md; `tests/test_heap.py`
counts them).  Frames of 1024^2 and more gain nothing measurable: their large
output arrays already raise glibc's own thresholds.

`keep_heap` raises both thresholds once per process through glibc's
``mallopt(3)``: blocks up to `MMAP_THRESHOLD` come from the heap, and the heap
keeps up to `TRIM_THRESHOLD` of free memory at its top (per arena: the main
thread's and one per rendering thread).  A warm frame then faults in no page.
The cost is that up to that much freed memory stays with the process instead
of going back to the system.  It changes no number the renderer computes.

The settings are process-wide (they are the C library's); they are applied on
the first call of `renderer.render`, `renderer.gbuffer` or `renderer.sweep`,
not on import.  Set the environment variable ``SYMRENDER_KEEP_HEAP=0`` before
that call to leave the allocator alone.  On a C library other than glibc
nothing is changed.

Source: glibc manual, "Malloc Tunable Parameters"; mallopt(3).
"""

from __future__ import annotations

import ctypes
import os
import platform
import threading

__all__ = ["keep_heap", "MMAP_THRESHOLD", "TRIM_THRESHOLD", "ENV_VAR"]

#: Blocks larger than this are still mapped on their own (bytes).  It is glibc's
#: largest dynamic threshold (32 MiB on 64-bit): a 4096^2 frame's outputs are
#: above it, every tile temporary is far below.
MMAP_THRESHOLD = 32 << 20
#: Free memory the top of a heap may hold before it is returned (bytes): several
#: tiles' working sets (about 26 MiB each, `renderer.render.TILE_PIXELS`).
TRIM_THRESHOLD = 64 << 20
#: Environment variable: "0" leaves the allocator alone.
ENV_VAR = "SYMRENDER_KEEP_HEAP"

# mallopt parameter numbers (glibc <malloc.h>).
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3

_lock = threading.Lock()
_state = {"applied": None}


def keep_heap():
    """Apply the two thresholds once per process; later calls return the first answer.

    Returns
    -------
    bool
        True if glibc accepted both settings (now or on an earlier call);
        False if ``SYMRENDER_KEEP_HEAP`` is "0", the C library is not glibc,
        or glibc refused a setting.  Never raises: the renderer works either
        way, only slower.
    """
    with _lock:
        if _state["applied"] is None:
            _state["applied"] = _apply()
        return _state["applied"]


def _apply():
    if os.environ.get(ENV_VAR, "1").strip() == "0":
        return False
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    ok = mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1
    return mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1 and ok
