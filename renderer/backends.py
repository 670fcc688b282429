"""Which array backends this machine has: Dr.Jit's LLVM backend, when the system's LLVM is there.

Dr.Jit (Jakob et al., "Dr.Jit: A Just-In-Time Compiler for Differentiable
Rendering", SIGGRAPH 2022) compiles array programs with LLVM at run time.  Its
pip wheel carries no LLVM: it loads the system's shared library (Debian's
``libllvm19``, or any version from `MIN_LLVM_VERSION` on; llvmlite's
statically linked LLVM cannot serve).  The library is found through the
environment variable ``DRJIT_LIBLLVM_PATH`` when it is set (set it to a path
that does not exist to switch the backend off), else the newest
``libLLVM-*.so*`` of at least that version in the system's library
directories.  Without one, `drjit_llvm` returns None and the numba kernel
renders.  A library that cannot serve may kill the process that loads it (a
truncated file: SIGBUS), so Dr.Jit loads it first in a child process (`probe`,
once per process): a refusal is one sentence naming the path and Dr.Jit's own
words, which it would otherwise print on stderr.  Dr.Jit's traces, frozen
functions and kernel launches are not safe from several threads at once (the
process aborts): the renderer runs them under one lock, `DRJIT_LOCK`.

The array namespaces (`NumpyNamespace`, `DrJitNamespace`) are what the
branch-free array kernel (`renderer.arraykernel`) and the generated array
formulas (renderer/generated_array.py) compute with: a few elementwise
functions, ``select`` and the conversion of a frame's outputs to numpy.
"""

from __future__ import annotations

import contextlib
import functools
import glob
import os
import re
import signal
import subprocess
import sys
import threading

import numpy as np

from .validate import InvalidValue

#: Where Debian and its derivatives put libLLVM (multiarch directory, then llvm-N/lib).
LIBRARY_PATTERNS = ("/usr/lib/*/libLLVM*.so*", "/usr/lib/llvm-*/lib/libLLVM*.so*", "/usr/lib64/libLLVM*.so*")

#: The oldest LLVM the backend uses.  Dr.Jit itself accepts 15, but its double-precision
#: ``atan2`` emits ``llvm.maximum``, which the x86 code generator of LLVM 15 and 16
#: cannot select: the process aborts ("LLVM ERROR: Cannot select ... fmaximum"; measured
#: with Debian's 15.0.6 and 16.0.6).  19.1 renders every frame of the test suite.
MIN_LLVM_VERSION = 17


def library_version(path):
    """The major version in an LLVM library's file name (``libLLVM-19.so.1`` -> 19), or None."""
    m = re.search(r"libLLVM[-.]?(\d+)", os.path.basename(path))
    return int(m.group(1)) if m else None


def llvm_library():
    """Path of the LLVM shared library Dr.Jit should load, or None.

    ``DRJIT_LIBLLVM_PATH`` when set (even to a missing file: that is how a
    user turns the backend off); else the newest major version among
    `LIBRARY_PATTERNS` (by the number in the name, ``libLLVM-19.so.1`` over
    ``libLLVM-17.so``) that is at least `MIN_LLVM_VERSION`.
    """
    if "DRJIT_LIBLLVM_PATH" in os.environ:
        return os.environ["DRJIT_LIBLLVM_PATH"]
    found = [p for pattern in LIBRARY_PATTERNS for p in glob.glob(pattern)
             if os.path.isfile(p) and (library_version(p) or 0) >= MIN_LLVM_VERSION]
    return max(found, key=lambda p: (library_version(p), p), default=None)


#: Held by every use of Dr.Jit by the renderer (`DrJitNamespace.scope`, loading it): Dr.Jit's
#: frozen functions and traces are not thread-safe (four threads rendering at once aborted the
#: process: "jit_var(...): unknown variable!").  Reentrant: a render loads Dr.Jit under it.
DRJIT_LOCK = threading.RLock()

#: What the child process of `probe` runs: the LLVM version Dr.Jit loaded, or nothing.
_PROBE = ("import drjit\n"
          "if drjit.has_backend(drjit.JitBackend.LLVM):\n"
          "    print(drjit.detail.llvm_version()[0])\n")
#: Longest the child of `probe` may take (seconds): it imports Dr.Jit and loads LLVM (0.2 s here).
PROBE_TIMEOUT = 60


@functools.cache
def probe(path):
    """(LLVM major version, None) when Dr.Jit's LLVM backend initialises with the library
    ``path``, else (None, why): tried in a child process (``DRJIT_LIBLLVM_PATH=path``), since
    loading a broken library can kill the process (a truncated file: SIGBUS), and Dr.Jit's
    own lines on stderr are returned in ``why`` rather than printed.  Cached per path."""
    try:
        child = subprocess.run([sys.executable, "-P", "-c", _PROBE], stdin=subprocess.DEVNULL, capture_output=True,
                               text=True, env={**os.environ, "DRJIT_LIBLLVM_PATH": path}, timeout=PROBE_TIMEOUT)
    except subprocess.TimeoutExpired:
        return None, f"loading it took more than {PROBE_TIMEOUT} s"
    except OSError as exc:
        return None, f"no process could be started to load it ({exc.strerror})"
    said = "; ".join(" ".join(line.split()) for line in child.stderr.splitlines() if line.strip())[-400:]
    if child.returncode < 0:
        try:
            name = signal.Signals(-child.returncode).name
        except ValueError:
            name = f"signal {-child.returncode}"
        return None, f"loading it killed the child process that tried ({name})" + (f": {said}" if said else "")
    if child.returncode or not child.stdout.strip().isdigit():
        return None, f"Dr.Jit could not load it: {said or 'no reason given'}"
    return int(child.stdout), None


def drjit_llvm():
    """The ``drjit.llvm`` module when Dr.Jit's LLVM backend works on this machine, else None.

    Checks `llvm_library` with `probe` (in a child process) before Dr.Jit is
    first imported here, sets ``DRJIT_LIBLLVM_PATH`` to it (if unset), then asks
    Dr.Jit whether the backend initialised; its warnings are silenced (its
    errors raise).  Decided once per process.  Never raises: a missing wheel or
    library, a library that cannot be loaded, or an LLVM older than
    `MIN_LLVM_VERSION` (which would abort the process on the first frame), is None.
    """
    with DRJIT_LOCK:
        return _drjit_llvm()


@functools.cache
def _drjit_llvm():
    import importlib.util
    path = llvm_library()
    if path is None or not os.path.isfile(path) or importlib.util.find_spec("drjit") is None:
        return None
    version, _ = probe(path)
    if version is None or version < MIN_LLVM_VERSION:
        return None
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", path)
    try:
        import drjit
        drjit.set_log_level(drjit.LogLevel.Error)
        if not drjit.has_backend(drjit.JitBackend.LLVM) or drjit.detail.llvm_version()[0] < MIN_LLVM_VERSION:
            return None
        import drjit.llvm
    except (ImportError, OSError, RuntimeError):
        return None
    return drjit.llvm


# ------------------------------------------------------------------ array namespaces
#: Backends of `renderer.render` (``backend=``): the numba kernel, the array kernel
#: (`renderer.arraykernel`) on numpy or on Dr.Jit's LLVM backend, and "auto".
BACKENDS = ("numba", "numpy", "drjit", "auto")


class NumpyNamespace:
    """The array namespace ``xp`` of `renderer.arraykernel` and `renderer.generated_array` on numpy.

    Always available: it runs the array kernel on any machine (the tests
    check its logic with it).  Arrays are 1-D float64 or bool numpy arrays;
    Python floats broadcast.  ``select(cond, a, b)`` is `numpy.where`.
    """

    name = "numpy"
    # Every function of `renderer.formulas.ELEMENTARY`, by math's name (a test checks each namespace).
    sin, cos, tan, asin, acos, atan = np.sin, np.cos, np.tan, np.asin, np.acos, np.atan
    sinh, cosh, tanh, exp, log, abs = np.sinh, np.cosh, np.tanh, np.exp, np.log, np.abs
    atan2, sqrt, hypot = np.arctan2, np.sqrt, np.hypot
    copysign, minimum, maximum, power = np.copysign, np.minimum, np.maximum, np.power
    select = staticmethod(np.where)

    @staticmethod
    def scope():
        """Context of a render: numpy's floating-point warnings off (a select computes
        both sides, and the side it drops may divide by 0)."""
        return np.errstate(all="ignore")

    @staticmethod
    def grid(cols, rows):
        """Per pixel of a block of ``len(rows)`` rows of ``len(cols)`` pixels, row-major:
        (cols[i], rows[j]), two float64 arrays of len(cols) * len(rows)."""
        return np.tile(cols, len(rows)), np.repeat(rows, len(cols))

    @classmethod
    def run(cls, program, s, structure, numbers, arrays, outputs, **options):
        """``program(xp, s, numbers, *arrays, **options)`` (a dict name -> list of arrays)
        as numpy arrays, (n, k) for k values per pixel, (n,) for one, of the dtypes of
        ``outputs`` (name -> (k, dtype)).  ``numbers`` (Python floats) are the values the
        program computes with, ``structure`` what of ``s`` it branches on (unused here)."""
        out = program(cls, s, numbers, *arrays, **options)
        return dict(zip(out, cls.numpy([(a, outputs[name][1]) for name, a in out.items()])))

    @staticmethod
    def numpy(groups):
        """Numpy arrays of ``groups``, pairs (arrays of n values, dtype): one array each,
        (n,) for one array, else (n, k) with the k arrays side by side."""
        return [(np.stack(a, axis=-1) if len(a) > 1 else np.asarray(a[0])).astype(d, copy=False)
                for a, d in groups]


#: Configurations (scene, options, block shape) of a frozen frame program Dr.Jit keeps.
FROZEN_CONFIGURATIONS = 32


class DrJitNamespace:
    """The array namespace on Dr.Jit's LLVM backend: ``drjit.llvm`` Float64 and Bool
    arrays, ``select`` is `drjit.select`.  Operations are traced, not run: `numpy`
    evaluates all outputs with one `drjit.eval`, so Dr.Jit compiles the frame into
    one kernel (cached in ~/.drjit after its first compile)."""

    name = "drjit"

    def __init__(self, llvm):
        import drjit as dr
        self.dr, self.Float64, self.UInt32, self.UInt8 = dr, llvm.Float64, llvm.UInt32, llvm.UInt8
        self.vector = {2: llvm.Array2f64, 3: llvm.Array3f64}
        self._frozen = {}
        # Every function of `renderer.formulas.ELEMENTARY`, by math's name, as NumpyNamespace's.
        self.sin, self.cos, self.tan, self.asin, self.acos = dr.sin, dr.cos, dr.tan, dr.asin, dr.acos
        self.atan, self.sinh, self.cosh, self.tanh = dr.atan, dr.sinh, dr.cosh, dr.tanh
        self.exp, self.log, self.abs, self.atan2, self.sqrt = dr.exp, dr.log, dr.abs, dr.atan2, dr.sqrt
        self.hypot = dr.hypot        # max |a|, |b| times sqrt(1 + ratio^2): no underflow of the squares
        self.copysign, self.minimum, self.maximum, self.power = dr.copysign, dr.minimum, dr.maximum, dr.power

    def select(self, cond, a, b):
        """`drjit.select`, with a Float64 result where both values are Python floats
        (drjit.select would give single precision)."""
        if isinstance(a, float) and isinstance(b, float):
            a = self.Float64(a)
        return self.dr.select(cond, a, b)

    @contextlib.contextmanager
    def scope(self):
        """Context of a render: `DRJIT_LOCK` held (one thread at a time traces, freezes and
        launches), and Dr.Jit's FastMath off while the frame is traced (it would fold
        a * 0 to 0 also where a is inf or NaN; IEEE arithmetic, as numba's)."""
        with DRJIT_LOCK, self.dr.scoped_set_flag(self.dr.JitFlag.FastMath, False):
            yield

    def grid(self, cols, rows):
        """As `NumpyNamespace.grid`, gathered inside the kernel from the two short arrays."""
        index = self.dr.arange(self.UInt32, len(cols) * len(rows))
        # The width as a kernel argument, not a literal: frames of any size share one compiled kernel.
        width = self.dr.opaque(self.UInt32, len(cols))
        return (self.dr.gather(self.Float64, self.Float64(cols), index % width),
                self.dr.gather(self.Float64, self.Float64(rows), index // width))

    def run(self, program, s, structure, numbers, arrays, outputs, **options):
        """As `NumpyNamespace.run`, with the traced program frozen (`drjit.freeze`):
        one frozen function per configuration (program, ``structure``, options,
        array lengths), which traces the program on its first call and replays
        the recorded kernel launch after.  ``numbers`` and ``arrays`` are the
        frozen function's inputs (``numbers`` as opaque Float64 values, not
        constants of the kernel): scenes of one structure differ only in them
        and share the kernel.  A frozen function never sees a second
        configuration: a replay keeps the buffer sizes and the branches it was
        recorded with.  At most `FROZEN_CONFIGURATIONS` are kept (least
        recently used first out)."""
        key = (program, structure, tuple(sorted(options.items())), tuple(len(a) for a in arrays))
        frozen = self._frozen.pop(key, None)
        if frozen is None:
            def record(numbers, arrays):
                out = program(self, s, numbers, *arrays, **options)
                return self.store([(a, outputs[name][1]) for name, a in out.items()], names=list(out))
            frozen = self.dr.freeze(record)
            while len(self._frozen) >= FROZEN_CONFIGURATIONS:
                self._frozen.pop(next(iter(self._frozen)))
        self._frozen[key] = frozen                          # the most recent last
        targets = frozen(tuple(self.dr.opaque(self.Float64, x) for x in numbers),
                         tuple(self.Float64(a) for a in arrays))
        return {name: np.asarray(t).view(outputs[name][1]).reshape((-1, outputs[name][0]) if outputs[name][0] > 1
                                                                    else (-1,)) for name, t in targets.items()}

    def store(self, groups, names):
        """Every group (arrays, dtype) scattered into a buffer of its own, a dict names -> buffer
        (unevaluated): a group of k arrays as one k-vector per pixel, interleaved."""
        dr, out = self.dr, {}
        n = max(dr.width(a) for arrays, _ in groups for a in arrays if isinstance(a, dr.ArrayBase))
        index = dr.arange(self.UInt32, n)
        for name, (arrays, dtype) in zip(names, groups):
            k = len(arrays)
            kind = self.UInt8 if dtype in (np.uint8, np.bool_) else self.Float64
            values = [kind(a) if isinstance(a, dr.ArrayBase) else dr.full(kind, a, n) for a in arrays]
            target = dr.empty(kind, n * k)                  # every element is written below
            dr.scatter(target, values[0] if k == 1 else self.vector[k](*values), index)
            out[name] = target
        return out

    def numpy(self, groups):
        """As `NumpyNamespace.numpy`, in one kernel launch: every output is scattered into
        a buffer of its own (a group of k arrays as one k-vector per pixel, interleaved),
        and one `drjit.eval` runs the frame's program and the stores together; the
        results are numpy views of Dr.Jit's memory (no copy)."""
        if not groups:
            return []
        out = list(self.store(groups, names=range(len(groups))).values())
        self.dr.eval(*out)
        return [np.asarray(a).view(d).reshape((-1, len(g)) if len(g) > 1 else (-1,))
                for a, (g, d) in zip(out, groups)]


def missing(name):
    """Why backend ``name`` cannot run here and how to get it (a sentence), or None when it can."""
    if name != "drjit" or drjit_llvm() is not None:
        return None
    return f"Dr.Jit's LLVM backend is unavailable: {_why_not()}; {_REMEDY}"


_REMEDY = (f"install the system's LLVM (Debian: apt-get install libllvm19) or set DRJIT_LIBLLVM_PATH to a "
           f"libLLVM-*.so of LLVM {MIN_LLVM_VERSION} or newer, or use backend 'numba' or 'auto'")


def _why_not():
    """What keeps Dr.Jit's LLVM backend off (`drjit_llvm` is None), naming the library's path."""
    import importlib.util
    path = llvm_library()
    if path is None:
        return (f"no libLLVM shared library of LLVM {MIN_LLVM_VERSION} or newer was found ("
                + ", ".join(LIBRARY_PATTERNS) + ")")
    if not os.path.isfile(path):
        return f"DRJIT_LIBLLVM_PATH is {path!r}, not a file"
    if importlib.util.find_spec("drjit") is None:
        return "the drjit package is not installed"
    named = f"DRJIT_LIBLLVM_PATH={path!r}" if "DRJIT_LIBLLVM_PATH" in os.environ else f"the LLVM library {path!r}"
    version, why = probe(path)
    if version is None:
        return f"{named} cannot serve: {why}"
    if version < MIN_LLVM_VERSION:
        return f"{named} is older than LLVM {MIN_LLVM_VERSION} (it is LLVM {version})"
    return f"Dr.Jit could not load the LLVM library {path!r}"


@functools.cache
def _note_fallback():
    """One line on stderr, once per process, when "auto" renders with numba although a
    libLLVM file is named or found (it cannot serve): silent where there is none, or where
    ``DRJIT_LIBLLVM_PATH`` names no file (how the backend is switched off)."""
    path = llvm_library()
    if path is not None and os.path.isfile(path) and sys.stderr is not None:
        print(f"symrender: backend 'auto' renders with numba: {_why_not()}", file=sys.stderr)


def resolve(name):
    """The backend that renders for an accepted ``name`` of `BACKENDS`: "auto" is
    "drjit" where Dr.Jit's LLVM backend works, else "numba" (with one line on stderr,
    once per process, when a libLLVM file exists but cannot serve: `_note_fallback`).

    Raises
    ------
    renderer.validate.InvalidValue
        ``name`` is "drjit" and Dr.Jit's LLVM backend is unavailable (the
        message says what is missing and how to get it).
    """
    if name == "auto":
        if drjit_llvm() is not None:
            return "drjit"
        _note_fallback()
        return "numba"
    why = missing(name)
    if why is not None:
        raise InvalidValue(f"backend must be one of {', '.join(map(repr, BACKENDS))} available on this "
                           f"machine, got {name!r}: {why}")
    return name


@functools.cache
def namespace(name):
    """The array namespace of backend "numpy" or "drjit" (`resolve` first)."""
    return NumpyNamespace() if name == "numpy" else DrJitNamespace(drjit_llvm())
