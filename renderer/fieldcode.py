"""The compiled code of a height field, or of a reader's function of one variable.

`renderer.codegen` prints a field's functions (`renderer.formulas.FIELD_FUNCTIONS`: h;
(h, h_u, h_v, crease flag) exact and by central differences; the crease flag) from its
`renderer.formulas.HeightField` record.  Here they are compiled, the same way for every
field:

* `compiled`: numba ``cfunc`` s, first-class functions that the render kernel
  (`renderer.kernel`) and the loops of `renderer.pointwise` call through pointers.  One
  compiled kernel thus serves every field; a field costs only its four small functions.
  A built-in field's functions (`formulas.BUILTIN`) are renderer/generated.py's, compiled
  once and cached on disk by numba beside it; any other field (registered later, or a
  reader's expression) is printed and compiled when first used in a process, and kept
  for the process (keyed by its record; a reader's expression finds its record again by
  its text, `formulas.field`).
* `array_code`: the branch-free array functions of the array kernel
  (`renderer.arraykernel`), renderer/generated_array.py's for a built-in field.
* `univariate_code`: f, and its central and forward differences, of a `univariate.Univariate`,
  as numba ``njit`` functions.

Calling a field's code through a pointer keeps it out of the kernel's inlining; the
exact and central functions therefore return h and the crease flag with the gradient, so
that one call per pixel shares their sines (measured at parity with the kernel that
inlined every field: benchmarks/bench_render.py).
"""

from __future__ import annotations

import math
import warnings
from collections import namedtuple
from functools import lru_cache

from numba import cfunc, njit, types
from numba.core.errors import NumbaExperimentalFeatureWarning

from . import _numba_cache
from . import formulas as F
from . import univariate as U

_numba_cache()          # where numba caches the built-in fields' functions (see renderer.kernel)

__all__ = ["FieldCode", "SIGNATURES", "compiled", "array_code", "univariate_code"]

_f8, _b1 = types.float64, types.boolean
_SAMPLE = types.Tuple((_f8, _f8, _f8, _b1))
#: The numba signature of each entry of `formulas.FIELD_FUNCTIONS`.
SIGNATURES = {"height": _f8(_f8, _f8, _f8, _f8), "exact": _SAMPLE(_f8, _f8, _f8, _f8),
              "central": _SAMPLE(_f8, _f8, _f8, _f8, _f8, _f8), "kink": _b1(_f8, _f8, _f8, _f8)}
#: A field's compiled functions, by the names of `formulas.FIELD_FUNCTIONS`.
FieldCode = namedtuple("FieldCode", tuple(F.FIELD_FUNCTIONS))

# numba calls first-class functions experimental; the kernel's use (cfuncs of fixed
# signatures, called) is the documented one.
warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning, message=".*[Ff]irst-class function")


def _execute(text, label, **namespace):
    namespace.setdefault("math", math)
    exec(compile(text, f"<{label}>", "exec"), namespace)      # noqa: S102 (text printed by renderer.codegen)
    return namespace


def _builtin(field):
    return field.name in F.BUILTIN and F.FIELDS.get(field.name) is field


def _generated(module, field):
    """A built-in field's functions in the generated ``module``; a field registered in formulas.py since the
    generator last ran has none there (RuntimeError, naming the command that prints them)."""
    try:
        return module.FIELDS[field.name]
    except KeyError:
        raise RuntimeError(f"{module.__name__} has no code for the height field {field.name!r} of renderer/formulas.py: "
                           "run python -m renderer.codegen") from None


@lru_cache(maxsize=None)
def compiled(field):
    """The `FieldCode` of a `formulas.HeightField`: numba cfuncs of `SIGNATURES`.

    Parameters
    ----------
    field : renderer.formulas.HeightField

    Returns
    -------
    FieldCode
        ``height(u, v, k_u, k_v) -> h``; ``exact(u, v, k_u, k_v)`` and
        ``central(u, v, k_u, k_v, eps_u, eps_v) -> (h, h_u, h_v, flag)``;
        ``kink(u, v, k_u, k_v) -> flag``.  float64 in and out, the flag a bool.

    Raises
    ------
    RuntimeError
        A built-in field (`formulas.BUILTIN`) renderer/generated.py does not hold: registered in
        formulas.py since ``python -m renderer.codegen`` last ran.
    """
    if _builtin(field):
        from . import generated
        functions, cache = _generated(generated, field), True
    else:
        from .codegen import field_source
        ns = _execute(field_source(field), f"height field {field.name}")
        functions, cache = [ns[name] for name in F.FIELD_FUNCTIONS], False
    return FieldCode(*(cfunc(SIGNATURES[name], cache=cache, error_model="numpy")(fn)
                       for name, fn in zip(F.FIELD_FUNCTIONS, functions)))


@lru_cache(maxsize=None)
def array_code(field):
    """The array functions of a `formulas.HeightField` (``name(xp, ...)``, as `compiled`'s over
    arrays of the namespace ``xp``), as a `FieldCode`."""
    if _builtin(field):
        from . import generated_array
        return FieldCode(*_generated(generated_array, field))
    from .codegen import field_source
    ns = _execute(field_source(field, array=True), f"height field {field.name}")
    return FieldCode(*(ns[name] for name in F.FIELD_FUNCTIONS))


#: A function of one variable's compiled functions (`univariate.FUNCTIONS`).
UnivariateCode = namedtuple("UnivariateCode", tuple(U.FUNCTIONS))


@lru_cache(maxsize=None)
def univariate_code(function):
    """``value(x)``, ``central(x, step)``, ``forward(x, step)`` of a `univariate.Univariate`, numba
    ``njit`` functions of float64 scalars (the abscissae x +- step rounded in float64, as a
    program computes them)."""
    from .codegen import univariate_source
    ns = _execute(univariate_source(function), f"function {function.name}")
    return UnivariateCode(*(njit(error_model="numpy")(ns[name]) for name in U.FUNCTIONS))
