"""Where the ridges field is not differentiable, and by how much (seed §3).

The theorem is about the renderer's ridges field and crease flag,
`renderer.formulas.HEIGHT["ridges"]`, `RIDGE_FACTORS` and `KINK_BAND`; the
jumps it states are written here by hand, from seed §3.
"""

import sympy as sp

from renderer import formulas as F

from .core import Identity, Theorem, check_identities

u, v = F.u, F.v
#: The frequencies are positive in the scene (Scene validates k_u, k_v > 0): the
#: one-sided limits below need it.
k_u, k_v = sp.symbols("k_u k_v", positive=True)
POSITIVE = {F.k_u: k_u, F.k_v: k_v}
delta = sp.Symbol("delta", positive=True)
x = sp.Symbol("x", real=True, nonzero=True)
#: The renderer's ridges field and its two factors.
h = F.HEIGHT["ridges"].subs(POSITIVE)
FACTORS = tuple(s.subs(POSITIVE) for s in F.RIDGE_FACTORS)
BAND = F.KINK_BAND["ridges"].subs(POSITIVE)
#: Every zero line at once: u = m / k_u and v = m / k_v for a symbolic integer m.
m = sp.Symbol("m", integer=True)
#: The other factor's value on the line, nonzero (where it is 0, h vanishes
#: along the whole line and there is no crease).
c = sp.Symbol("c", real=True, nonzero=True)
DOMAIN = {u: (0.0, 1.0), v: (0.0, 1.0), k_u: (0.5, 12.0), k_v: (0.5, 12.0), c: (-1.0, 1.0)}
#: The crease flag's half-width (seed Cell 1, ``height1``: |s1| < 0.03 or |s2| < 0.03).
SEED_HALF_WIDTH = sp.Rational(3, 100)


def one_sided(expr, var, at):
    """(right, left) derivatives of ``expr`` in ``var`` at ``var = at``."""
    base = expr.subs(var, at)
    right = sp.limit((expr.subs(var, at + delta) - base) / delta, delta, 0, "+")
    left = sp.limit((base - expr.subs(var, at - delta)) / delta, delta, 0, "+")
    return sp.simplify(right), sp.simplify(left)


def _flag(condition):
    """1 where the crease flag's condition holds, 0 where it does not."""
    return sp.Piecewise((sp.Integer(1), condition), (sp.Integer(0), True))


def _identities(jump_u, jump_v, band):
    ids = [Identity(r"\frac{d}{dx}\lvert x\rvert,\ x \ne 0", sp.diff(sp.Abs(x), x), sp.sign(x),
                    {x: (-3.0, 3.0)}),
           Identity(r"h = \lvert s_1 s_2\rvert", h, sp.Abs(FACTORS[0] * FACTORS[1]), DOMAIN)]
    for var, k, peak, factor, other, hand, jump in (
            (u, k_u, {v: 1 / (2 * k_v)}, FACTORS[0], FACTORS[1], s2_hand, jump_u),
            (v, k_v, {u: 1 / (2 * k_u)}, FACTORS[1], FACTORS[0], s1_hand, jump_v)):
        line = m / k
        r, l = one_sided(h.subs(other, c), var, line)
        ids += [Identity(rf"h_{var}^+ - h_{var}^-\ \text{{at}}\ {var} = m/k_{var}", r - l, jump.subs(hand, c), DOMAIN),
                Identity(rf"s\ \text{{at}}\ {var} = m/k_{var}", factor.subs(var, line), sp.Integer(0), DOMAIN),
                Identity(rf"\text{{crease flag at}}\ {var} = m/k_{var}", _flag(band.subs(var, line)),
                         sp.Integer(1), DOMAIN)]
        # The band's edge: where the other factor is 1 (``peak``) and this one is just inside or
        # just outside the seed's half-width, the flag is set and not set.
        ids += [Identity(rf"\text{{crease flag at}}\ \lvert s\rvert = {float(w):.8g},\ {var}",
                         _flag(band.subs(peak).subs(var, sp.asin(w) / (sp.pi * k))), sp.Integer(flag), DOMAIN)
                for w, flag in ((SEED_HALF_WIDTH * (1 - sp.Rational(1, 10**6)), 1),
                                (SEED_HALF_WIDTH * (1 + sp.Rational(1, 10**6)), 0))]
    return ids


def _check(jump_u, jump_v, band=BAND):
    return check_identities(_identities(jump_u, jump_v, band))


#: The jumps, written by hand (seed §3): independent of the renderer's expressions.
s1_hand, s2_hand = sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_v * v)
JUMP_U = 2 * sp.pi * k_u * sp.Abs(s2_hand)
JUMP_V = 2 * sp.pi * k_v * sp.Abs(s1_hand)

RIDGES_KINKS = Theorem(
    id="ridges-kinks", title="The creases of the ridges field",
    statement=r"The renderer's ridges field (`renderer.formulas.HEIGHT['ridges']`) "
              r"$h = \lvert s_1 s_2\rvert$ with $s_1 = \sin\pi k_u u$, $s_2 = \sin\pi k_v v$ "
              r"(`RIDGE_FACTORS`) is "
              r"differentiable wherever $s_1 s_2 \ne 0$, with gradient $\operatorname{sign}(s_1 s_2)\,\nabla(s_1 s_2)$. "
              r"On every zero line $u = m/k_u$ ($m$ any integer) the one-sided derivatives in $u$ differ by "
              r"$2\pi k_u \lvert\sin\pi k_v v\rvert$, and on $v = m/k_v$ those in $v$ by "
              r"$2\pi k_v \lvert\sin\pi k_u u\rvert$: a crease wherever the other factor is nonzero. "
              r"The renderer's crease flag (`KINK_BAND`) is set on every zero line, and where "
              rf"$\lvert s_1\rvert < {float(SEED_HALF_WIDTH):g}$ or $\lvert s_2\rvert < {float(SEED_HALF_WIDTH):g}$ "
              r"(the seed's half-width) only.",
    # The identities take one-sided limits: built when checked, not on import.
    check=lambda: _check(JUMP_U, JUMP_V),
    wrong_variants=(
        ("jump without the factor 2", lambda: _check(sp.pi * k_u * sp.Abs(s2_hand), JUMP_V)),
        ("jump with the roles of k_u and k_v swapped", lambda: _check(2 * sp.pi * k_v * sp.Abs(s2_hand), JUMP_V)),
        ("the crease band ten times wider",
         lambda: _check(JUMP_U, JUMP_V, BAND.xreplace({F.KINK_BAND_HALF_WIDTH: 10 * F.KINK_BAND_HALF_WIDTH}))),
        ("the crease band half as wide",
         lambda: _check(JUMP_U, JUMP_V, BAND.xreplace({F.KINK_BAND_HALF_WIDTH: F.KINK_BAND_HALF_WIDTH / 2})))),
    steps=((r"one-sided", r"(h_u^+, h_u^-)\big|_{u = m/k_u,\ \sin\pi k_v v = c \ne 0}",
            sp.Tuple(*one_sided(h.subs(FACTORS[1], c), u, m / k_u))),
           (r"h_u^+ - h_u^-", r"h_u^+ - h_u^-", JUMP_U),
           (r"h_v^+ - h_v^-", r"h_v^+ - h_v^-", JUMP_V),
           (r"crease flag", r"\text{KINK\_BAND}", BAND)),
    pages=("s3", "s7"),
)

THEOREMS = (RIDGES_KINKS,)
