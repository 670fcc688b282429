"""Where a field with creases is not differentiable, and by how much (seed §3).

One theorem (``<name>-kinks``) per registered field with creases whose two crease factors
(`renderer.formulas.HeightField.crease_factors`) vary one with u, the other with v: the
ridges field of seed §3.  It is about the field's record: its expression, its crease factors
and its crease flag (`HeightField.kink_band`); the jumps it states are written here by hand,
from seed §3, for the factors s_1 = sin(pi k_u u), s_2 = sin(pi k_v v) (a field with other
factors gets the theorem, and its check refutes it).
"""

from functools import lru_cache

import sympy as sp

from renderer import formulas as F

from . import gradients as G
from .core import Step, Theorem, calc, written

u, v = F.u, F.v
#: The frequencies are positive in the scene (Scene validates k_u, k_v > 0): the
#: one-sided limits below need it.
k_u, k_v = sp.symbols("k_u k_v", positive=True)
POSITIVE = {F.k_u: k_u, F.k_v: k_v}
delta = sp.Symbol("delta", positive=True)
SUFFIX = "-kinks"
#: Every zero line at once: u = m / k_u and v = m / k_v for a symbolic integer m.
m = sp.Symbol("m", integer=True)
LINE_U, LINE_V = m / k_u, m / k_v
#: The other factor's value on the line, nonzero (where it is 0, h vanishes
#: along the whole line and there is no crease).
c = sp.Symbol("c", real=True, nonzero=True)
DOMAIN = {u: (0.0, 1.0), v: (0.0, 1.0), k_u: (0.5, 12.0), k_v: (0.5, 12.0), c: (-1.0, 1.0)}
#: The crease flag's half-width (seed Cell 1, ``height1``: |s1| < 0.03 or |s2| < 0.03).
SEED_HALF_WIDTH = sp.Rational(3, 100)

#: The seed's half-width and the relative margin of the points just inside and just outside it,
#: named in the proof (their values in its ``where``: 3/100 and 10^-6).
W, ETA = sp.symbols("w eta", positive=True)
MARGIN = sp.Rational(1, 10**6)

#: The one-sided derivatives the proof names: h_u^+, h_u^- on u = m/k_u, h_v^+, h_v^- on v = m/k_v.
HU_P, HU_M, HV_P, HV_M = sp.symbols("h_u^+ h_u^- h_v^+ h_v^-")
#: The renderer's crease flag as a function of (u, v): 1 where the field's band holds, else 0.
crease = sp.Function("crease")
#: Points just inside and just outside the crease band about u = 0 and v = 0.
U_IN, U_OUT, V_IN, V_OUT = sp.symbols("u_in u_out v_in v_out")


def _at(expr, var, point):
    """``expr`` with ``var`` replaced by ``point``, rebuilt unevaluated and kept as written
    (`written`): sin(pi k_u (m/k_u - delta)), not sympy's -sin(pi k_u (delta - m/k_u))."""
    def rebuild(e):
        if e == var or not e.args:
            return point if e == var else e
        args = map(rebuild, e.args)
        return e.func(*(sorted(args, key=lambda a: a.has(point)) if e.is_Mul else args), evaluate=False)
    return written(rebuild(expr))


def one_sided(expr, var, at):
    """(right, left) derivatives of ``expr`` in ``var`` at ``var = at``, as unevaluated limits."""
    base = expr.subs(var, at)
    return tuple(sp.Limit(sign * (_at(expr, var, sp.Add(at, sign * delta, evaluate=False)) - base) / delta,
                          delta, 0, "+") for sign in (1, -1))


def creased():
    """The names of the registered fields the theorem is about: those with two crease factors
    (`HeightField.crease_factors`), one varying with u alone, the other with v alone."""
    return tuple(name for name, f in F.FIELDS.items()
                 if [x.free_symbols & {u, v} for x in f.crease_factors] == [{u}, {v}])


def band_of(field):
    """The field's crease flag (`HeightField.kink_band`) for positive frequencies."""
    return field.kink_band.subs(POSITIVE)


def _creases(field, jump_u, jump_v, band=None):
    """Theorem <name>-kinks of ``field`` claiming the jumps ``jump_u``, ``jump_v`` (in c), for the crease band
    ``band`` (default: the field's, `band_of`)."""
    name, band = field.name, band_of(field) if band is None else band
    h, factors = field.expr.subs(POSITIVE), tuple(f.subs(POSITIVE) for f in field.crease_factors)
    on_u = one_sided(h.subs(factors[1], c), u, LINE_U)
    on_v = one_sided(h.subs(factors[0], c), v, LINE_V)
    named = G.named_factors(field)
    jumps, values = sp.Tuple(HU_P - HU_M, HV_P - HV_M), sp.Tuple(jump_u, jump_v)
    on_lines = sp.Tuple(crease(LINE_U, v), crease(u, LINE_V))
    # Just inside and just outside the seed's half-width: |s| = w (1 -+ eta), where the other factor is 1.
    w_in, w_out = (sp.asin(W * (1 + s * ETA), evaluate=False) for s in (-1, 1))
    edges = {"u": sp.Tuple(crease(U_IN, 1 / (2 * k_v)), crease(U_OUT, 1 / (2 * k_v))),
             "v": sp.Tuple(crease(1 / (2 * k_u), V_IN), crease(1 / (2 * k_u), V_OUT))}
    return Theorem(
        id=name + SUFFIX, title=_title(name),
        statement=f"The renderer's {name} field "
                  r"$⟦h⟧$, the product of its two factors $⟦s_1⟧$ and $⟦s_2⟧$, is differentiable wherever "
                  r"$⟦smooth⟧$, by ⟪gradient-" + name + "⟫. "
                  r"On every zero line $⟦line_u⟧$ ($m$ any integer), where the other factor is $⟦c⟧$, its graph "
                  r"has a crease: the one-sided derivatives $h_u^+$ and $h_u^-$ (the slopes just right and just "
                  r"left of the line) differ, and so do $h_v^\pm$ on $⟦line_v⟧$: $⟦jumps⟧$."
                  "\n\n"
                  r"*Corollary (the renderer's crease band).* A central difference whose two points straddle a "
                  r"crease returns neither one-sided slope, so the renderer flags the pixels near a crease, and "
                  r"the book reports their error apart. Its crease flag is 1 on every zero line, $⟦lines⟧$, and "
                  r"exactly where $⟦band⟧$: a band about "
                  rf"${float(SEED_HALF_WIDTH):g}/(\pi k_u)$ wide in $u$ on each side of a line (likewise in $v$); "
                  r"the threshold is the draft's.",
        steps=(
            *calc(sp.Tuple(HU_P, HU_M),
                  (r"On the line $u = m/k_u$ the factor $s_1 = \sin\pi k_u u$ vanishes; with $c \ne 0$ the value of "
                   r"$s_2$ there, the one-sided derivatives of $h = \lvert s_1 c\rvert$ in $u$ are the limits",
                   sp.Tuple(*on_u)),
                  (r"$\lvert\sin\pi k_u u\rvert$ is a V about its zero, of slopes $\pm\pi k_u$",
                   sp.Tuple(k_u * sp.pi * sp.Abs(c), -k_u * sp.pi * sp.Abs(c)))),
            Step(r"So they differ by $2\pi k_u\lvert c\rvert$; the same limits with $u$ and $v$ exchanged give "
                 r"$h_v^\pm$ on $v = m/k_v$", jumps, values),
            Step("For the corollary: on both lines one factor is 0, inside the band, so the flag is set",
                 on_lines, sp.Tuple(1, 1)),
            Step(r"The band's edge is the half-width $w$: on the line where $s_2 = 1$, take $u_-$ where "
                 r"$\lvert s_1\rvert = w\,(1 - \eta)$, a hair (the relative margin $\eta$) inside the band, and "
                 r"$u_+$ where $\lvert s_1\rvert = w\,(1 + \eta)$, a hair outside; the flag is 1 at $u_-$ and "
                 r"0 at $u_+$", edges["u"], sp.Tuple(1, 0),
                 defines=(U_IN, U_OUT, W, ETA)),
            Step(r"Likewise across $v$, where $s_1 = 1$", edges["v"], sp.Tuple(1, 0), defines=(V_IN, V_OUT)),
        ),
        claims={"jumps": (jumps, values), "lines": (on_lines, sp.Tuple(1, 1))},
        shown={"h": sp.Eq(F.h, G.shown(field), evaluate=False), "smooth": sp.Ne(sp.Mul(*named), 0),
               "c": sp.Ne(c, 0, evaluate=False), "line_u": sp.Eq(u, LINE_U), "line_v": sp.Eq(v, LINE_V),
               "band": band.xreplace({e.subs(POSITIVE): s for s, e in named.items()})},
        where={HU_P: on_u[0], HU_M: on_u[1], HV_P: on_v[0], HV_M: on_v[1],
               crease: sp.Lambda((u, v), sp.Piecewise((1, band), (0, True))),
               U_IN: w_in / (sp.pi * k_u), U_OUT: w_out / (sp.pi * k_u), V_IN: w_in / (sp.pi * k_v),
               V_OUT: w_out / (sp.pi * k_v), W: SEED_HALF_WIDTH, ETA: MARGIN, **named},
        names={HU_P: r"h_u^+", HU_M: r"h_u^-", HV_P: r"h_v^+", HV_M: r"h_v^-", crease: r"\mathrm{crease}",
               U_IN: "u_-", U_OUT: "u_+", V_IN: "v_-", V_OUT: "v_+", ETA: r"\eta"},
        domain=DOMAIN,
        wrong_variants=(
            ("jump without the factor 2", lambda: _creases(field, sp.pi * k_u * sp.Abs(c), JUMP_V).check()),
            ("jump with the roles of k_u and k_v swapped",
             lambda: _creases(field, 2 * sp.pi * k_v * sp.Abs(c), JUMP_V).check()),
            ("the crease band ten times wider",
             lambda: _creases(field, JUMP_U, JUMP_V, band.xreplace({F.KINK_BAND_HALF_WIDTH: 10 * F.KINK_BAND_HALF_WIDTH})
                             ).check()),
            ("the crease band half as wide",
             lambda: _creases(field, JUMP_U, JUMP_V, band.xreplace({F.KINK_BAND_HALF_WIDTH: F.KINK_BAND_HALF_WIDTH / 2})
                             ).check())),
    )


#: The jumps, written by hand (seed §3), with c the other factor's value on the line.
JUMP_U = 2 * sp.pi * k_u * sp.Abs(c)
JUMP_V = 2 * sp.pi * k_v * sp.Abs(c)


def _title(name):
    return f"The creases of the {name} field"


def titles():
    """{id: title} of this module's theorems, one per field of `creased`."""
    return {name + SUFFIX: _title(name) for name in creased()}


def build(theorem_id):
    """Theorem <name>-kinks of the registered field <name>, built once per field record."""
    return _built(F.FIELDS[theorem_id.removesuffix(SUFFIX)])


@lru_cache(maxsize=None)
def _built(field):
    return _creases(field, JUMP_U, JUMP_V)


build.cache_clear = _built.cache_clear
