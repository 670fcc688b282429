"""Theorems as objects: a statement, the sympy steps of the argument, a check.

A check returns a `Verdict`:

* ``proved``: sympy decided every identity exactly (lhs - rhs reduces to 0 under
  ``expand``, ``simplify`` or ``trigsimp``);
* ``verified``: sympy could not decide, and every identity holds at >= 20
  seeded random points evaluated with mpmath at 30 significant digits, with
  the worst residual stated;
* ``refuted``: some identity fails, with the residual or counterexample.

Each theorem also carries *wrong variants* (a flipped sign, a dropped factor,
a wrong exponent) that the same checker must refute: the checker has teeth.
(SymPy's ``sympy/vector`` tests and mpmath's precision discipline are the
models.)
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import Callable

import mpmath
import sympy as sp

__all__ = ["Verdict", "Identity", "Theorem", "check_identities", "identities_theorem",
           "step_parts", "DIGITS", "POINTS"]

#: Working precision of numerical verification, in significant decimal digits.
DIGITS = 30
#: Number of seeded random points for numerical verification.
POINTS = 24
#: A residual below 10**(-TOLERANCE_DIGITS) at DIGITS of precision counts as zero.
TOLERANCE_DIGITS = 20


@dataclass(frozen=True)
class Verdict:
    """Outcome of a theorem's check."""

    status: str                   # "proved" | "verified" | "refuted"
    evidence: str                 # one line a reader can check
    residual: float | None = None  # worst |lhs - rhs| found numerically (None if exact)
    digits: int | None = None
    points: int | None = None
    rendered: int = 0              # renderer outputs (pixels, or frames) the check compared

    @property
    def holds(self) -> bool:
        return self.status in ("proved", "verified")


@dataclass(frozen=True)
class Identity:
    """lhs == rhs for all values of ``domain``'s symbols.

    ``domain`` maps each free symbol to an interval (lo, hi) from which the
    numerical fallback samples.
    """

    label: str
    lhs: sp.Expr
    rhs: sp.Expr
    domain: dict = field(default_factory=dict)
    #: For identities about an undefined function h: concrete instances
    #: {h: Lambda(...)} substituted only for numerical sampling.
    functions: dict = field(default_factory=dict)


def _exactly_zero(expr) -> bool:
    expr = sp.sympify(expr)
    if expr == 0:
        return True
    for simplifier in (sp.expand, sp.simplify, lambda e: sp.simplify(sp.expand_trig(e)), sp.trigsimp):
        try:
            if simplifier(expr) == 0:
                return True
        except (TypeError, ValueError, NotImplementedError):  # pragma: no cover - sympy limits
            continue
    return False


def _numeric_residual(identity: Identity, seed: int, points: int, digits: int):
    """Worst |lhs - rhs| of a scalar identity over seeded random points, and the point where it occurs."""
    diff = sp.sympify(identity.lhs - identity.rhs)
    if identity.functions:
        diff = diff.subs(identity.functions).doit()
    free = sorted(diff.free_symbols, key=lambda s: s.name)
    missing = [s for s in free if s not in identity.domain]
    if missing:
        raise ValueError(f"identity {identity.label!r}: no sampling interval for {missing}")
    fn = sp.lambdify(free, diff, modules="mpmath")
    rng = random.Random(seed)
    worst, where = mpmath.mpf(0), None
    with mpmath.workdps(digits):
        for _ in range(points):
            point = {s: mpmath.mpf(rng.uniform(*identity.domain[s])) for s in free}
            r = abs(fn(*[point[s] for s in free]))
            if not r <= worst or where is None:     # NaN is the worst residual
                worst, where = r, point
                if mpmath.isnan(r):
                    break
    return float(worst), where


def check_identities(identities, *, seed=0, points=POINTS, digits=DIGITS) -> Verdict:
    """Decide a list of `Identity`.

    Per component: a quick numerical probe (3 points) looks for a
    counterexample first, which refutes at once; otherwise sympy tries to
    prove the identity exactly; what sympy cannot decide is verified at
    ``points`` seeded points with ``digits`` digits, or refuted.
    """
    components = []
    for ident in identities:
        as_matrix = lambda e: e if isinstance(e, sp.MatrixBase) else sp.Matrix([e])  # noqa: E731
        lhs, rhs = as_matrix(ident.lhs), as_matrix(ident.rhs)
        if lhs.shape != rhs.shape:
            return Verdict("refuted", f"{ident.label}: shapes {lhs.shape} and {rhs.shape} differ")
        for k, (a, b) in enumerate(zip(lhs, rhs)):
            label = ident.label if lhs.shape == (1, 1) else f"{ident.label}[{k}]"
            components.append(Identity(label, a, b, ident.domain, ident.functions))
    tolerance = 10.0 ** (-TOLERANCE_DIGITS)

    def refuted(r, label, at):
        where = ", ".join(f"{k}={float(v):.6g}" for k, v in (at or {}).items())
        return Verdict("refuted", f"{label}: residual {r:.3e} at {where}", residual=r,
                       digits=digits, points=points)

    undecided = []
    for i, comp in enumerate(components):
        r, at = _numeric_residual(comp, seed + 1000 + i, 3, digits)
        if not r < tolerance:                       # a NaN residual refutes as well
            return refuted(r, comp.label, at)
        if not _exactly_zero(comp.lhs - comp.rhs):
            undecided.append(comp)
    if not undecided:
        return Verdict("proved", f"{len(components)} identities, lhs - rhs reduced to 0 by sympy")
    worst, worst_label, worst_at = 0.0, None, None
    for i, comp in enumerate(undecided):
        r, at = _numeric_residual(comp, seed + i, points, digits)
        if not r < worst:                           # NaN included: it is kept, and refutes
            worst, worst_label, worst_at = r, comp.label, at
    if worst < tolerance:
        return Verdict("verified",
                       f"{len(undecided)} of {len(components)} identities not decided by sympy; "
                       f"worst residual {worst:.1e} ({worst_label}) at {points} seeded points, "
                       f"{digits} digits", residual=worst, digits=digits, points=points)
    return refuted(worst, worst_label, worst_at)


@dataclass(frozen=True)
class Theorem:
    """A theorem of the chapter.

    Attributes
    ----------
    id : str            stable identifier (cited by the book and verify/)
    title : str
    statement : str     LaTeX
    steps : tuple       (caption, lhs, rhs) triples of sympy objects or LaTeX strings
                        (rhs may be None):
                        the argument a reader sees, rendered as lhs = rhs
    check : callable    () -> Verdict
    wrong_variants : tuple of (description, callable () -> Verdict); each must be refuted
    pages : tuple       book pages that use the theorem
    seed_says : str     what the seed claims, where it makes a claim about this
    """

    id: str
    title: str
    statement: str
    steps: tuple
    check: Callable[[], Verdict]
    wrong_variants: tuple
    pages: tuple = ()
    seed_says: str = ""


def identities_theorem(id, title, statement, identities, variants, *, steps=(), pages=(),
                       seed_says=""):
    """A `Theorem` whose check is `check_identities` on ``identities``.

    ``variants`` is a sequence of (description, list of Identity) that must be refuted.
    """
    identities = tuple(identities)
    steps = tuple(steps) or tuple((i.label, i.lhs, i.rhs) for i in identities)
    return Theorem(
        id=id, title=title, statement=statement, steps=steps,
        check=lambda: check_identities(identities),
        wrong_variants=tuple((d, (lambda ids=tuple(v): check_identities(ids))) for d, v in variants),
        pages=tuple(pages), seed_says=seed_says,
    )


def step_parts(step):
    """(lhs, rhs) of one (caption, lhs, rhs) step as LaTeX strings (rhs None if absent); sympy
    objects are printed, with the symbol phi as the book's \\varphi."""
    _, lhs, rhs = step

    def tex(e):                       # a str is LaTeX already
        if e is None or isinstance(e, str):
            return e
        return sp.latex(e, symbol_names={s: r"\varphi" for s in getattr(e, "free_symbols", ()) if s.name == "phi"})
    return tex(lhs), tex(rhs)


