"""The built-in fields are the seed's: an independent statement of each formula, against the records.

Every theorem about a field derives its objects from the field's record (`renderer.formulas.FIELDS`),
so a record with a wrong expression is wrong consistently everywhere, and the theorems about it
still hold.  What pins the records is the seed's own text: its §2 defines the three fields and its
Cell 2 states their gradients (h_u, h_v), written out below as sympy once, from the seed, not from
the records.  A field registered later (a reader's, or a fourth built-in) has no seed statement and
is not compared here.
"""

import numpy as np
import pytest
import sympy as sp

from renderer import formulas as F
from renderer.formulas import k_u, k_v, u, v

_s1, _s2 = sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_v * v)
_sigma = sp.sign(_s1 * _s2)

#: name: (h, (h_u, h_v)), as the seed states them (§2; Cell 2, "The gradients").
SEED_FIELDS = {
    "sine": (_s1 * _s2, (sp.pi * k_u * sp.cos(sp.pi * k_u * u) * _s2, sp.pi * k_v * _s1 * sp.cos(sp.pi * k_v * v))),
    "ridges": (sp.Abs(_s1 * _s2), (sp.pi * k_u * sp.cos(sp.pi * k_u * u) * _s2 * _sigma,
                                   sp.pi * k_v * _s1 * sp.cos(sp.pi * k_v * v) * _sigma)),
    "rings": (sp.sin(2 * sp.pi * k_v * v), (sp.Integer(0), 2 * sp.pi * k_v * sp.cos(2 * sp.pi * k_v * v))),
}


def seed_mismatches(fields, points=64, seed=2026):
    """Lines naming each seed field missing from ``fields`` ({name: HeightField}) or whose expression,
    h_u or h_v differs from the seed's by more than 1e-12 (relative to 1 + |value|) at ``points``
    random chart points and frequencies in [1, 16] (off the creases: sign() is 0 on them, where the
    seed leaves the gradient undefined)."""
    rng = np.random.default_rng(seed)
    uv = rng.uniform(0, 1, (2, points))
    ks = rng.uniform(1, 16, (2, points))
    bad = []
    for name, (h, grad) in SEED_FIELDS.items():
        if name not in fields:
            bad.append(f"{name}: the seed's field is not registered")
            continue
        record = fields[name]
        for what, mine, theirs in zip(("h", "h_u", "h_v"), (record.expr, *record.gradient), (h, *grad)):
            f, g = (np.vectorize(sp.lambdify(F.FIELD_SYMBOLS, e, modules="math"), otypes=[float])
                    for e in (mine, theirs))
            a, b = f(*uv, *ks), g(*uv, *ks)
            worst = float(np.max(np.abs(a - b) / (1 + np.abs(b))))
            if not worst <= 1e-12:
                bad.append(f"{name}: {what} is not the seed's ({worst:.2e} apart)")
    return bad


def test_the_built_in_fields_are_the_seeds():
    assert seed_mismatches(F.FIELDS) == []


@pytest.mark.parametrize("name, wrong", [
    ("rings", sp.sin(2 * sp.pi * k_u * v)),                  # the frequency from k_u
    ("sine", _s1 * sp.sin(sp.pi * k_u * v)),                 # both factors with k_u
    ("ridges", _s1 * _s2),                                   # the Abs dropped
])
def test_a_record_that_is_not_the_seeds_is_named(name, wrong):
    fields = {**F.FIELDS, name: F.HeightField(name, wrong)}
    assert any(line.startswith(f"{name}: h is not the seed's") for line in seed_mismatches(fields))
    assert seed_mismatches({n: f for n, f in F.FIELDS.items() if n != name}) == \
        [f"{name}: the seed's field is not registered"]
