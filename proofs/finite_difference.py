"""Central differences: the truncation series and the optimal step (seed §3)."""

import sympy as sp

from .core import Identity, Theorem, Verdict, check_identities, identities_theorem

x = sp.Symbol("x", real=True)
eps = sp.Symbol("varepsilon", positive=True)
f = sp.Function("h")
ORDER = 6


def central_series(order=ORDER):
    """Series of (h(x + eps) - h(x - eps)) / (2 eps) in eps, up to O(eps**order)."""
    q = (f(x + eps) - f(x - eps)) / (2 * eps)
    return sp.series(q, eps, 0, order).removeO().doit()


CLAIMED = (sp.diff(f(x), x) + eps**2 / 6 * sp.diff(f(x), x, 3)
           + eps**4 / 120 * sp.diff(f(x), x, 5))

a, b = sp.symbols("a b", real=True)
#: A concrete analytic h for numerical sampling only (the proof is for any h).
INSTANCE = {f: sp.Lambda(x, sp.sin(a * x) + sp.exp(b * x))}
SERIES_DOMAIN = {x: (-1.0, 1.0), eps: (0.01, 0.3), a: (0.5, 3.0), b: (-1.0, 1.0)}


def _series_identity(rhs):
    return Identity("series", central_series(), rhs, SERIES_DOMAIN, INSTANCE)


CENTRAL_DIFFERENCE_TRUNCATION = identities_theorem(
    "central-difference-truncation", "Truncation error of the central difference",
    r"$\dfrac{h(x+\varepsilon) - h(x-\varepsilon)}{2\varepsilon} = h' + \dfrac{\varepsilon^2}{6}h''' + "
    r"\dfrac{\varepsilon^4}{120}h^{(5)} + O(\varepsilon^6)$.",
    [_series_identity(CLAIMED)],
    [("coefficient 1/3 instead of 1/6",
      [_series_identity(CLAIMED + eps**2 / 6 * sp.diff(f(x), x, 3))]),
     ("eps^3 instead of eps^2",
      [_series_identity(CLAIMED - eps**2 / 6 * sp.diff(f(x), x, 3) + eps**3 / 6 * sp.diff(f(x), x, 3))])],
    pages=("s3",),
)

H3, H, u_round = sp.symbols("H_3 H u", positive=True)
ERROR_MODEL = eps**2 * H3 / 6 + u_round * H / eps
EPS_STAR = (3 * u_round * H / H3) ** sp.Rational(1, 3)


def _optimum(claimed):
    stationary = sp.solve(sp.Eq(sp.diff(ERROR_MODEL, eps), 0), eps)
    curvature = sp.simplify(sp.diff(ERROR_MODEL, eps, 2).subs(eps, claimed))
    ids = [Identity("stationary point", sp.diff(ERROR_MODEL, eps).subs(eps, claimed), sp.Integer(0),
                    {H3: (1.0, 1e4), H: (0.1, 1.0), u_round: (1e-17, 1e-15)})]
    verdict = check_identities(ids)
    if not verdict.holds:
        return verdict
    if len(stationary) != 1 or not (curvature.is_positive):
        return Verdict("refuted", f"stationary points {stationary}, curvature {curvature}")
    return Verdict(verdict.status, f"the unique positive stationary point of the model; "
                   f"second derivative {sp.latex(curvature)} > 0; {verdict.evidence}")


OPTIMAL_STEP = Theorem(
    id="optimal-step", title="The optimal central-difference step",
    statement=r"The error model $E(\varepsilon) = \varepsilon^2\lvert h'''\rvert/6 + "
              r"\mathrm{u}\lvert h\rvert/\varepsilon$ ($\mathrm{u}$ the unit roundoff) has its "
              r"minimum at $\varepsilon^\ast = (3\mathrm{u}\lvert h\rvert/\lvert h'''\rvert)^{1/3}$.",
    steps=((r"derivative", r"E'(\varepsilon)", sp.diff(ERROR_MODEL, eps)),
           (r"\varepsilon^\ast", r"\varepsilon^\ast", EPS_STAR)),
    check=lambda: _optimum(EPS_STAR),
    wrong_variants=(("exponent 1/2 instead of 1/3",
                     lambda: _optimum((3 * u_round * H / H3) ** sp.Rational(1, 2))),),
    pages=("s3", "s5", "s7"),
    seed_says="§3: truncation dominates until eps ~ 1e-6; Cell 2 expects the minimum near 1e-6.",
)

THEOREMS = (CENTRAL_DIFFERENCE_TRUNCATION, OPTIMAL_STEP)
