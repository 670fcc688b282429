"""Where the ridges field is not differentiable, and by how much (seed §3)."""

import sympy as sp

from renderer import fields

from .core import Identity, identities_theorem

u, v = fields.u, fields.v
k_u, k_v = sp.symbols("k_u k_v", positive=True)
delta = sp.Symbol("delta", positive=True)
x = sp.Symbol("x", real=True, nonzero=True)
s1, s2 = sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_v * v)
h = sp.Abs(s1 * s2)
DOMAIN = {u: (0.0, 1.0), v: (0.0, 1.0), k_u: (0.5, 12.0), k_v: (0.5, 12.0)}
#: Zero lines checked: u = m / k_u and v = m / k_v for these m.
LINES = (0, 1, 2, 3)


def one_sided(expr, var, at):
    """(right, left) derivatives of ``expr`` in ``var`` at ``var = at``."""
    base = expr.subs(var, at)
    right = sp.limit((expr.subs(var, at + delta) - base) / delta, delta, 0, "+")
    left = sp.limit((base - expr.subs(var, at - delta)) / delta, delta, 0, "+")
    return sp.simplify(right), sp.simplify(left)


def _identities(jump_u, jump_v):
    ids = [Identity(r"\frac{d}{dx}\lvert x\rvert,\ x \ne 0", sp.diff(sp.Abs(x), x), sp.sign(x),
                    {x: (-3.0, 3.0)})]
    for m in LINES:
        r, l = one_sided(h, u, sp.Integer(m) / k_u)
        ids.append(Identity(rf"h_u^+ - h_u^-\ \text{{at}}\ u = {m}/k_u", r - l, jump_u, DOMAIN))
        r, l = one_sided(h, v, sp.Integer(m) / k_v)
        ids.append(Identity(rf"h_v^+ - h_v^-\ \text{{at}}\ v = {m}/k_v", r - l, jump_v, DOMAIN))
    return ids


JUMP_U = 2 * sp.pi * k_u * sp.Abs(s2)
JUMP_V = 2 * sp.pi * k_v * sp.Abs(s1)

RIDGES_KINKS = identities_theorem(
    "ridges-kinks", "The creases of the ridges field",
    r"$h = \lvert s_1 s_2\rvert$ with $s_1 = \sin\pi k_u u$, $s_2 = \sin\pi k_v v$ is "
    r"differentiable wherever $s_1 s_2 \ne 0$, with gradient $\operatorname{sign}(s_1 s_2)\,\nabla(s_1 s_2)$. "
    r"On the zero line $u = m/k_u$ the one-sided derivatives in $u$ differ by "
    r"$2\pi k_u \lvert\sin\pi k_v v\rvert$, and on $v = m/k_v$ those in $v$ by "
    r"$2\pi k_v \lvert\sin\pi k_u u\rvert$: a crease wherever the other factor is nonzero.",
    _identities(JUMP_U, JUMP_V),
    [("jump without the factor 2", _identities(sp.pi * k_u * sp.Abs(s2), JUMP_V)),
     ("jump with the roles of k_u and k_v swapped", _identities(2 * sp.pi * k_v * sp.Abs(s2), JUMP_V))],
    steps=((r"one-sided", r"(h_u^+, h_u^-)\big|_{u = 1/k_u}", sp.Tuple(*one_sided(h, u, 1 / k_u))),
           (r"h_u^+ - h_u^-", r"h_u^+ - h_u^-", JUMP_U),
           (r"h_v^+ - h_v^-", r"h_v^+ - h_v^-", JUMP_V)),
    pages=("s3", "s7"),
)

THEOREMS = (RIDGES_KINKS,)
