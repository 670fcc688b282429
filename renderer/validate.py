"""Argument validation: one function per kind of value, the same acceptance wherever it is used.

`renderer.Scene` and `PointLight`, `renderer.pointwise`, `renderer.ucurve` and the
command line (``symrender``) check their arguments with these functions:

* a real scalar (`real`): a Python ``int`` or ``float``, a numpy integer or floating
  scalar (``np.float32(0.5)``, ``np.int64(3)``), or a 0-d numeric array (numpy's own
  spelling of a scalar), any other `numbers.Real` (``Fraction``); returned as a float;
* a real array (`real_array`): anything numpy turns into a numeric array (scalars,
  nested lists, arrays of any integer or floating dtype); returned as float64;
* a 3-vector (`vector3`): a tuple, list or 1-D array of three real scalars;
* a flag (`flag`): ``True`` or ``False`` (Python's or numpy's);
* a choice (`choice`): one of a tuple of strings;
* a positive integer (`positive_int`): an ``int`` or numpy integer >= 1;
* steps (`steps`): a non-empty array of step sizes within a range;
* a thread count (`thread_count`): numba's ``NUMBA_NUM_THREADS``, in [1, `MAX_THREADS`].

Refused everywhere: a bool where a number is asked (``True`` is not 1.0, in an array
either), complex numbers, strings (numpy would parse ``"0.5"``), containers without an
order (a set, a dict), masked arrays (numpy would drop the mask), non-finite numbers, and
an integer too large for a float (``10**400``).

Each refusal is an `InvalidValue` (a ValueError) or an `InvalidType` (a
TypeError); both are `InputError`, which the command line reports as an input
error (exit 2) rather than a bug.  The message names the parameter, the value
and what is accepted.
"""

from __future__ import annotations

import numbers
import os
import sys

import numpy as np

__all__ = ["InputError", "InvalidValue", "InvalidType", "real", "real_array", "vector3", "flag",
           "choice", "positive_int", "steps", "thread_count", "MAX_THREADS"]


class InputError(Exception):
    """An argument refused by validation: the caller's input, not a bug.  The message
    starts with the parameter's name."""


class InvalidValue(InputError, ValueError):
    """An argument of the right type with a value outside what is accepted."""


class InvalidType(InputError, TypeError):
    """An argument of a type that is not accepted."""


def _shown(value, limit=80):
    """``value`` for a message: its type and repr, cut to ``limit`` characters (an int too
    long for repr is described by its size)."""
    if isinstance(value, int) and value.bit_length() > 3 * sys.get_int_max_str_digits():
        return f"an integer of {value.bit_length():,} bits"
    try:
        text = " ".join(repr(value).split())     # an array's repr spans lines
    except ValueError:                           # it holds an int too long for repr
        return f"a {type(value).__name__} holding an integer of more than {sys.get_int_max_str_digits()} digits"
    text = text if len(text) <= limit else text[:limit] + "..."
    return f"{type(value).__name__} {text}"


def _accepted(low, high, low_open, high_open):
    """``in [low, high]``, ``> low``, ``<= high``, ... or ``finite``."""
    if low is not None and high is not None:
        return f"in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
    if low is not None:
        return f"{'>' if low_open else '>='} {low:g}"
    if high is not None:
        return f"{'<' if high_open else '<='} {high:g}"
    return "finite"


def _inside(x, low, high, low_open, high_open):
    """Whether ``x`` (a float or a float64 array) is finite and within the range, elementwise."""
    ok = np.isfinite(x)
    if low is not None:
        ok = ok & ((x > low) if low_open else (x >= low))
    if high is not None:
        ok = ok & ((x < high) if high_open else (x <= high))
    return ok


def _too_large(value):
    """Digits of an int too large for a float, as words."""
    try:
        return f"an integer of {len(str(abs(value)))} digits"
    except ValueError:                           # beyond Python's int-to-str limit
        return f"an integer of more than {sys.get_int_max_str_digits()} digits"


def real(name, value, *, low=None, high=None, low_open=False, high_open=False):
    """``value`` as a finite float within a range.

    Parameters
    ----------
    name : str
        The parameter named in errors.
    value : real scalar
        A Python or numpy integer or floating scalar, a 0-d numeric array, or another
        `numbers.Real`; not a bool.
    low, high : float or None
        The bounds (None: unbounded on that side); ``low_open``, ``high_open`` exclude them.

    Returns
    -------
    float

    Raises
    ------
    InvalidType
        ``value`` is not a real scalar (a bool, a string, a complex number, an array of
        more than 0 dimensions, None, ...).
    InvalidValue
        ``value`` is not finite, too large for a float, or outside the range.
    """
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InvalidType(f"{name} must be a real number, got {_shown(value)}")
    accepted = _accepted(low, high, low_open, high_open)
    try:
        x = float(value)
    except OverflowError:                        # an integer beyond float64's range
        raise InvalidValue(f"{name} must be {accepted}, got {_too_large(int(value))}") from None
    if not _inside(x, low, high, low_open, high_open):
        raise InvalidValue(f"{name} must be {accepted}, got {value!r}")
    return x


def real_array(name, value, *, low=None, high=None, low_open=False, high_open=False):
    """``value`` as a float64 array of finite numbers within a range.

    Parameters
    ----------
    name : str
    value : array_like of real numbers
        Any shape; integer and floating dtypes (a nested list of numbers, a scalar).
    low, high, low_open, high_open
        As `real`.

    Returns
    -------
    ndarray of float64, the shape of ``value`` (not a copy if it already is one).

    Raises
    ------
    InvalidType
        Not real numbers: a bool or bool array, complex numbers, strings, objects, a
        ragged list.
    InvalidValue
        A non-finite entry, an integer too large for a float, or an entry outside the
        range; the message gives the first such entry and its flat index.
    """
    def wrong_type():
        return InvalidType(f"{name} must be real numbers (a scalar or an array), got {_shown(value, 60)}")

    accepted = _accepted(low, high, low_open, high_open)
    if isinstance(value, np.ma.MaskedArray):     # np.asarray would drop the mask
        raise InvalidType(f"{name} must be real numbers (a scalar or an array), got a masked array: "
                          f"fill it (numpy.ma.filled) or select its unmasked values (.compressed())")
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):              # a ragged list
        raise wrong_type() from None
    if not isinstance(value, np.ndarray) and raw.dtype.kind in "iuf" and _holds_bool(value):
        raise InvalidType(f"{name} must be real numbers, not bools (True is not 1.0), got {_shown(value, 60)}")
    if raw.dtype.kind == "O" and all(isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))
                                     for x in raw.flat):
        try:
            raw = raw.astype(np.float64)         # Python ints beyond int64, Fractions
        except OverflowError:
            raise InvalidValue(f"{name} must be {accepted}, got an integer too large for a float") from None
    if raw.dtype.kind not in "iuf":
        raise wrong_type()
    a = raw.astype(np.float64, copy=False)
    bad = np.flatnonzero(~_inside(a, low, high, low_open, high_open))
    if bad.size:
        raise InvalidValue(f"{name} must be {accepted}, got {float(a.reshape(-1)[bad[0]])!r} "
                           f"at flat index {bad[0]}")
    return a


def _holds_bool(value):
    """Whether a nested list or tuple holds a bool (numpy reads ``[True, 0.5]`` as [1.0, 0.5])."""
    if isinstance(value, (bool, np.bool_)):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype.kind == "b" or (value.dtype.kind == "O" and any(map(_holds_bool, value.flat)))
    return isinstance(value, (list, tuple)) and any(map(_holds_bool, value))


def vector3(name, value, *, low=None, high=None):
    """``value`` as a tuple of three finite floats, each within [low, high].

    Accepted: a tuple, a list or a 1-D array of three real scalars (as `real`).

    Raises
    ------
    InvalidType
        Another container (a set, a dict, a string, a 0-d or 2-D array) or a component
        that is not a real scalar (named ``name[i]``).
    InvalidValue
        Not three components, or a component not finite or outside the range (``name[i]``).
    """
    if not (isinstance(value, (tuple, list)) or (isinstance(value, np.ndarray) and value.ndim == 1)):
        raise InvalidType(f"{name} must be a sequence of 3 real numbers (a tuple, list or 1-D array), "
                          f"got {_shown(value)}")
    if len(value) != 3:
        raise InvalidValue(f"{name} must have exactly 3 components, got {len(value)}: {_shown(value)}")
    return tuple(real(f"{name}[{i}]", c, low=low, high=high) for i, c in enumerate(value))


def flag(name, value):
    """``value`` as a bool: ``True`` or ``False``, Python's or numpy's (or a 0-d bool array).

    Raises
    ------
    InvalidType
        Anything else (``1``, ``"no"``, None): a number or a string would read as a truth value.
    """
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidType(f"{name} must be True or False, got {_shown(value)}")
    return bool(value)


def choice(name, value, accepted):
    """``value`` if it is one of the strings ``accepted`` (a tuple).

    Raises
    ------
    InvalidType
        ``value`` is not a string.
    InvalidValue
        ``value`` is a string not in ``accepted`` (matched exactly: case and spaces count).
    """
    if not isinstance(value, str):
        raise InvalidType(f"{name} must be one of {accepted}, got {_shown(value)}")
    if value not in accepted:
        raise InvalidValue(f"{name} must be one of {accepted}, got {value!r:.80}")
    return str(value)


def positive_int(name, value, *, high=None):
    """``value`` as an int in [1, high] (``high`` None: no upper bound).

    Accepted: a Python or numpy integer (or a 0-d integer array); not a bool or a float.

    Raises
    ------
    InvalidType
        Not an integer.
    InvalidValue
        Below 1 or above ``high``.
    """
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise InvalidType(f"{name} must be a positive integer, got {_shown(value)}")
    n = int(value)
    if n < 1 or (high is not None and n > high):
        accepted = "a positive integer" if high is None else f"an integer in [1, {high}]"
        raise InvalidValue(f"{name} must be {accepted}, got {_shown(n) if n.bit_length() > 64 else n}")
    return n


def steps(name, value, *, low, high, high_open=False, max_count=None):
    """``value`` as a 1-D float64 array of step sizes, each in [low, high] (or [low, high)).

    Parameters
    ----------
    name : str
    value : array_like of real numbers
        A scalar (one step) or an array of any shape (flattened, in order); not a set.
    low, high : float
        The accepted steps; ``high_open`` excludes ``high``.
    max_count : int or None
        Most steps accepted (None: any number).

    Raises
    ------
    InvalidType
        As `real_array`; or an unordered container (a set, a dict).
    InvalidValue
        No steps, more than ``max_count``, or a step outside the range (with its index).
    """
    if isinstance(value, (set, frozenset, dict)):
        raise InvalidType(f"{name} must be ordered steps (a list, tuple or array), got {_shown(value)}")
    a = real_array(name, value, low=low, high=high, high_open=high_open).reshape(-1)
    if a.size == 0 or (max_count is not None and a.size > max_count):
        count = "at least one step" if max_count is None else f"1 to {max_count} steps"
        raise InvalidValue(f"{name} must hold {count}, got {a.size}")
    return a


#: Most threads `thread_count` accepts: 64, or the machine's CPUs where it has more (numba's
#: default is one per CPU).  NUMBA_NUM_THREADS=100000 made numba's thread pool segfault.
MAX_THREADS = max(64, os.cpu_count() or 1)


def thread_count(name, value):
    """``value``, a count of threads (an int, or the text of an environment variable such as
    numba's ``NUMBA_NUM_THREADS``), as an int in [1, `MAX_THREADS`].

    Raises
    ------
    InvalidValue
        Not the digits of an integer, or outside [1, `MAX_THREADS`] (the message names
        ``name``, the value and the range).
    """
    try:
        n = int(value) if isinstance(value, (int, str)) and not isinstance(value, bool) else None
    except ValueError:
        n = None
    if n is None or not 1 <= n <= MAX_THREADS:
        shown = repr(value[:40]) + ("..." if len(value) > 40 else "") if isinstance(value, str) else _shown(value)
        raise InvalidValue(f"{name} must be an integer in [1, {MAX_THREADS}] (a count of threads: at most 64, "
                           f"or this machine's CPUs where more), got {shown}")
    return n


#: Longest expression text accepted (characters): a height field or a function is a formula, not a program.
MAX_EXPRESSION_CHARS = 500
#: The largest exponent of a power of numbers `expression` evaluates: 2**1100 is past float64 already.
MAX_NUMBER_EXPONENT = 1100


def _huge_exponent(exponent):
    """Whether ``exponent`` (a sympy expression of numbers, unevaluated) is beyond `MAX_NUMBER_EXPONENT`
    in size, evaluating none of its own powers that are (9**9**9's exponent 9**9 is evaluated, its power not)."""
    import sympy as sp
    if any(isinstance(p, sp.Pow) and _huge_exponent(p.exp) for p in exponent.args):
        return True
    return abs(sp.N(exponent, 5)) > MAX_NUMBER_EXPONENT


def expression(name, text, symbols, functions, *, fields=()):
    """The sympy expression written in ``text``, in the variables ``symbols``.

    ``text`` is parsed by ``sympy.parse_expr`` in a namespace of the variables, ``pi``,
    ``E`` and the ``functions`` (``abs`` and ``sqrt`` too), and
    nothing else: every name is checked against it first, so no other name (no builtin,
    no attribute, no sympy function outside it) can be reached.  ``^`` is a power.

    Parameters
    ----------
    name : str
        The parameter named in errors.
    text : str
        The expression, e.g. ``"sin(pi*k_u*u)**2 * sin(pi*k_v*v)**2"``.
    symbols : tuple of sympy.Symbol
        The variables it may use, by their names.
    functions : tuple of sympy function classes
        The functions it may call, by their names (`renderer.formulas.ELEMENTARY`).
    fields : tuple of str
        Names that would also have been accepted (listed in the error of an unknown name).

    Returns
    -------
    sympy.Expr

    Raises
    ------
    InvalidType
        ``text`` is not a string.
    InvalidValue
        Empty, longer than `MAX_EXPRESSION_CHARS`, a name outside the namespace, an
        operator other than + - * / ** ^ and parentheses, or text that is not an expression.
    """
    import io
    import keyword
    import tokenize

    import sympy as sp
    from sympy.parsing.sympy_parser import auto_number, convert_xor, parse_expr

    if not isinstance(text, str):
        raise InvalidType(f"{name} must be a string, got {_shown(text)}")
    if not text.strip() or len(text) > MAX_EXPRESSION_CHARS:
        raise InvalidValue(f"{name} must be an expression of 1 to {MAX_EXPRESSION_CHARS} characters, "
                           f"got {len(text)}")
    namespace = {str(s): s for s in symbols}
    namespace.update({f.__name__: f for f in functions}, abs=sp.Abs, sqrt=sp.sqrt, pi=sp.pi, E=sp.E)
    functions = sorted(k for k, f in namespace.items() if callable(f) and not isinstance(f, sp.Basic))
    accepted = (f"an expression in {', '.join(map(str, symbols))} (with pi, E, + - * / ** and "
                f"{', '.join(functions)})" + (f" or one of {', '.join(fields)}" if fields else ""))
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (tokenize.TokenError, SyntaxError, IndentationError):
        raise InvalidValue(f"{name} must be {accepted}; {text!r:.80} does not parse") from None
    for tok in tokens:
        if tok.type == tokenize.NAME and (tok.string not in namespace or keyword.iskeyword(tok.string)):
            raise InvalidValue(f"{name} must be {accepted}; {tok.string!r} is not one of its names")
        if tok.type == tokenize.OP and tok.string not in ("+", "-", "*", "/", "**", "^", "(", ")", ","):
            raise InvalidValue(f"{name} must be {accepted}; {tok.string!r} is not one of its operators")
        if tok.type not in (tokenize.NAME, tokenize.OP, tokenize.NUMBER, tokenize.NEWLINE, tokenize.NL,
                            tokenize.ENDMARKER):
            raise InvalidValue(f"{name} must be {accepted}; {tok.string!r} is not part of one")
        if tok.type == tokenize.NUMBER and tok.string[-1] in "jJ":
            raise InvalidValue(f"{name} must be real; {tok.string!r} is imaginary")
    glob = {"__builtins__": {}, "Integer": sp.Integer, "Float": sp.Float, "Rational": sp.Rational}
    try:
        # First unevaluated: a power of numbers past float64 (9**9**9) would take sympy hours to evaluate.
        held = parse_expr(text, local_dict=namespace, global_dict={**glob, "Add": sp.Add, "Mul": sp.Mul, "Pow": sp.Pow},
                          transformations=(auto_number, convert_xor), evaluate=False)
        power = next((p for p in sp.preorder_traversal(held) if isinstance(p, sp.Pow) and p.exp.is_number
                      and not p.exp.free_symbols and _huge_exponent(p.exp)), None)
        if power is None:
            expr = parse_expr(text, local_dict=namespace, global_dict=glob, transformations=(auto_number, convert_xor))
    except (SyntaxError, TypeError, ValueError, AttributeError, ZeroDivisionError) as exc:
        raise InvalidValue(f"{name} must be {accepted}; {text!r:.80} is not one ({exc})") from None
    if power is not None:
        raise InvalidValue(f"{name} must hold only numbers float64 can; {text!r:.80} raises a number to the "
                           f"power {str(power.exp):.40}")
    if not isinstance(expr, sp.Expr):
        raise InvalidValue(f"{name} must be {accepted}; {text!r:.80} is a {type(expr).__name__}")
    return expr
