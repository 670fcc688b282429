"""Which array backends this machine has: Dr.Jit's LLVM backend, when the system's LLVM is there.

Dr.Jit (Jakob et al., "Dr.Jit: A Just-In-Time Compiler for Differentiable
Rendering", SIGGRAPH 2022) compiles array programs with LLVM at run time.  Its
pip wheel carries no LLVM: it loads the system's shared library (Debian's
``libllvm19`` or another version; llvmlite's statically linked LLVM cannot
serve).  The library is found through the environment variable
``DRJIT_LIBLLVM_PATH`` when it is set (set it to a path that does not exist to
switch the backend off), else the newest ``libLLVM-*.so*`` in the system's
library directories.  Without one, `drjit_llvm` returns None and the numba
kernel renders.
"""

from __future__ import annotations

import functools
import glob
import os
import re

#: Where Debian and its derivatives put libLLVM (multiarch directory, then llvm-N/lib).
LIBRARY_PATTERNS = ("/usr/lib/*/libLLVM*.so*", "/usr/lib/llvm-*/lib/libLLVM*.so*", "/usr/lib64/libLLVM*.so*")


def llvm_library():
    """Path of the LLVM shared library Dr.Jit should load, or None.

    ``DRJIT_LIBLLVM_PATH`` when set (even to a missing file: that is how a
    user turns the backend off); else the newest major version among
    `LIBRARY_PATTERNS` (by the number in the name, ``libLLVM-19.so.1`` over
    ``libLLVM-15.so``).
    """
    if "DRJIT_LIBLLVM_PATH" in os.environ:
        return os.environ["DRJIT_LIBLLVM_PATH"]
    found = [p for pattern in LIBRARY_PATTERNS for p in glob.glob(pattern) if os.path.isfile(p)]

    def version(path):
        m = re.search(r"libLLVM[-.]?(\d+)", os.path.basename(path))
        return int(m.group(1)) if m else -1
    return max(found, key=lambda p: (version(p), p), default=None)


@functools.cache
def drjit_llvm():
    """The ``drjit.llvm`` module when Dr.Jit's LLVM backend works on this machine, else None.

    Sets ``DRJIT_LIBLLVM_PATH`` to `llvm_library` (if unset) before Dr.Jit
    is first imported, then asks Dr.Jit whether the backend initialised.
    Never raises: a missing wheel or library is None.
    """
    path = llvm_library()
    if path is None:
        return None
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", path)
    try:
        import drjit
        if not drjit.has_backend(drjit.JitBackend.LLVM):
            return None
        import drjit.llvm
    except (ImportError, OSError, RuntimeError):
        return None
    return drjit.llvm
