"""`renderer.ucurve.measure`'s arguments: each bad one is refused by name.

Each message is matched whole, from its start: the parameter's name, what is
accepted and the value, so that a message naming another parameter (or any
ValueError at all) does not pass.  The accepted values at each limit are
measured (a few steps each).
"""

from fractions import Fraction

import numpy as np
import pytest

from renderer.pointwise import MIN_STEP
from renderer.ucurve import measure
from renderer.validate import InputError


def refusal(kwargs):
    """The (type, message) `measure` raises for ``kwargs`` (one step unless given)."""
    with pytest.raises(InputError) as info:
        measure(**{"eps": [1e-3], **kwargs})
    return TypeError if isinstance(info.value, TypeError) else ValueError, str(info.value)


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(field="bumps"), ValueError, "field must be one of ('sine', 'ridges', 'rings'), got 'bumps'"),
    (dict(field=1), TypeError, "field must be one of ('sine', 'ridges', 'rings'), got int 1"),
    (dict(component="w"), ValueError, "component must be one of ('u', 'v'), got 'w'"),
    (dict(u=1.5), ValueError, "u must be in [0, 1], got 1.5"),
    (dict(u=-0.0 - 1e-300), ValueError, "u must be in [0, 1], got -1e-300"),
    (dict(v=1.0000000000000002), ValueError, "v must be in [0, 1], got 1.0000000000000002"),
    (dict(v=float("nan")), ValueError, "v must be in [0, 1], got nan"),
    (dict(u=True), TypeError, "u must be a real number, got bool True"),
    (dict(v="0.5"), TypeError, "v must be a real number, got str '0.5'"),
    (dict(u=np.array([0.5])), TypeError, "u must be a real number, got ndarray array([0.5])"),
    (dict(k_u=0.0), ValueError, "k_u must be in (0, 1000], got 0.0"),
    (dict(k_v=1000.0000000000001), ValueError, "k_v must be in (0, 1000], got 1000.0000000000001"),
    (dict(k_u=10**400), ValueError, "k_u must be in (0, 1000], got an integer of 401 digits"),
    (dict(k_v=np.True_), TypeError, "k_v must be a real number, got bool np.True_"),
    (dict(eps=[1e-3, -1e-3]), ValueError, "eps must be in [1e-300, 1), got -0.001 at flat index 1"),
    (dict(eps=[1.0]), ValueError, "eps must be in [1e-300, 1), got 1.0 at flat index 0"),
    (dict(eps=[np.nextafter(MIN_STEP, 0)]), ValueError,
     f"eps must be in [1e-300, 1), got {float(np.nextafter(MIN_STEP, 0))!r} at flat index 0"),
    (dict(eps=[]), ValueError, "eps must hold at least one step, got 0"),
    (dict(eps=[True]), TypeError, "eps must be real numbers (a scalar or an array), got list [True]"),
    (dict(eps={1e-3}), TypeError, "eps must be ordered steps (a list, tuple or array), got set {0.001}"),
])
def test_bad_arguments_are_named(kwargs, error, message):
    assert refusal(kwargs) == (error, message)


@pytest.mark.parametrize("kwargs", [
    dict(u=0.0), dict(u=1.0), dict(v=0), dict(v=np.float32(0.5)), dict(u=np.array(0.25)), dict(u=Fraction(1, 3)),
    dict(k_u=1e3), dict(k_v=5e-324), dict(k_u=np.int64(3)),
    dict(eps=[MIN_STEP, np.nextafter(1.0, 0.0)]), dict(eps=np.float32(1e-3)),
])
def test_values_at_the_limits_and_numpy_scalars_are_measured(kwargs):
    uc = measure(**{"eps": [1e-3], **kwargs})
    assert np.all(np.isfinite(uc.error)) and uc.eps.dtype == np.float64
    for name in ("u", "v"):
        value = kwargs.get(name)
        if value is not None:
            assert getattr(uc, name) == float(value) and type(getattr(uc, name)) is float
