"""`renderer.ucurve.measure`'s arguments: each bad one is refused by name."""

import pytest

from renderer.ucurve import measure


@pytest.mark.parametrize("kwargs, fragment", [
    (dict(field="bumps"), "field"), (dict(component="w"), "component"), (dict(u=1.5), "u"),
    (dict(eps=[1e-3, -1e-3]), "eps"), (dict(eps=[]), "eps"), (dict(k_u=0.0), "k_u"),
])
def test_bad_arguments_are_named(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        measure(**kwargs)
