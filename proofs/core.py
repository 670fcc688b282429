"""Theorems as derivations: a statement, a chain of steps a person reads, each step checked.

A proof is a sequence of `Step`s.  Each step is one sentence (why it holds) and one
equation ``lhs = rhs`` between sympy objects, and each is decided on its own by
`check_identities`:

* ``proved``: sympy reduces lhs - rhs to 0 (``expand``; sin² = 1 - cos² over a common
  denominator, `_circle_reduced`; ``simplify`` or ``trigsimp``);
* ``verified``: sympy could not decide, and lhs - rhs vanishes at `POINTS` seeded
  random points evaluated with mpmath at `DIGITS` significant digits (worst residual
  stated);
* ``refuted``: a residual, or a counterexample, naming the theorem, the step's number
  and its sentence.

Steps form calc chains, as in Lean's ``calc``: a step with ``link=True`` continues
the one before it, its lhs being that step's rhs (`calc` builds such chains; a link
whose lhs is not the previous rhs must be decided equal to it, or the proof is
refuted).  A theorem's ``claims`` are the equations its statement makes, which the book
prints into the statement (``⟦key⟧``) from these same objects; each must be the two ends of a run of one
chain, so the steps are checked to reach the statement, not trusted to.

A step may name a quantity by a symbol (``E``, ``N``, ``\\varepsilon^\\ast``) that the
theorem's ``where`` defines: the step prints the name, and is checked with the
definition substituted.  `Dot`, `Cross` and `Jacobian` stay as written (the book prints
them, book/chapter/latex.py) and evaluate when checked; unevaluated sympy forms (``Derivative``, ``Limit``,
``Subs``, ``UnevaluatedExpr``) likewise, so that a theorem module builds its steps
cheaply and the check does the work.

After the steps, a theorem's ``evidence`` (the renderer's outputs compared with the
statement) must hold too.  Each theorem carries *wrong variants* that the same check
must refute: the checker has teeth.  (SymPy's ``sympy/vector`` tests and mpmath's
precision discipline are the models.)

The rules the checker enforces, no correct theorem breaking them being no evidence that
they hold (tests/test_core.py and tests/test_checker.py plant a violation of each):

1. *Citing.*  ``using`` names earlier steps only, ``1 <= j < k`` for step k (an int):
   never the step itself, a later one or step 0; each cited left side is a name (or a
   tuple of names), replaced by that step's right side, and the step contains that name (one
   of them at least: its sides, or the definitions of ``where`` they reach).
2. *Chains.*  A ``link`` continues the step before it, never step 1; its left side is
   that step's right side, or is decided equal to it with the link's rewrites and cases.
   A claim is reached by a run of one chain: its left side a step's, its right side the
   same or a later step's, every step between them a link.
3. *The cache.*  `_DECIDED` reuses a verdict only under the same key: both sides after
   every substitution (``where``, the rewrites, the case), the domain, the sampled
   functions, the seed, points and digits of the numbers (`SEED`, `POINTS`, `DIGITS`) and the
   tolerance that counts a residual as zero (`TOLERANCE_DIGITS`).
4. *Series.*  Only a right side may carry an O-term: one, a term of its sum, in one
   variable about a finite point, ``O((x - x0)**n)``.  The step holds when the series of
   lhs - rhs (less the O-term) vanishes through (x - x0)**(n - 1).  A written term that
   the O-term contains (``c*x**4 + O(x**4)``, kept by `written` or ``evaluate=False``) is
   refused, not absorbed.
5. *Evidence.*  Asked only once every step holds and every claim is reached; it returns a
   `Verdict`, and anything but proved or verified refutes; verified evidence states a
   finite residual and its points; its ``rendered`` count is the theorem's.
6. *Numbers.*  A residual counts as zero below 10**-`TOLERANCE_DIGITS` at `DIGITS`
   digits, the worst of `POINTS` seeded points; a NaN, or a point where the difference
   cannot be evaluated, refutes.
7. *Pins* (proofs/registry.py).  A verdict passes its pin only as "proved" for a pin
   "proved", or as "verified" with a residual at most ``bound`` for ("verified", bound),
   bound 0.0 included; with at least its `RENDERED` count of renderer outputs, and at most
   `RENDERED_SHARE` times it (a minimum far below the evidence would let most of it go unseen).
8. *Citations.*  A statement or a step's sentence names another theorem only by the marker
   ``⟪id⟫`` (`CITATION`), never by its id in words; the id must be a theorem of the registry
   (`CITABLE`, which reads proofs/registry.py's), or the theorem is refuted.  The book prints the marker as
   "Theorem n (title)", plain text (`plain`) as its title.  The registry's citations form no cycle
   (`citation_cycle`, which verify/test_theorems.py holds): no theorem rests on itself.
9. *Claims* (lab/claims.py).  A claim of the draft reaches its registered verdict from
   finite measurements, by its criterion, whose thresholds are the ones its words state.
10. *Placeholders.*  A statement shows mathematics only through ``⟦key⟧`` (`PLACEHOLDER`): a claim,
   a named symbol of ``where`` or an object of ``shown``, which the book prints
   (book/chapter/latex.py); a key that is none of these refutes, and so does a relation typed in
   its mathematics (`TYPED_RELATION`: =, <, >, ``\\le``, ``\\ne``, ``\\to``, ``\\in`` and the like), whose sides no
   object holds: the typed math may name symbols and write operations, never assert.
11. *Thresholds.*  An evidence's threshold (`Verdict.bound`) and a verified pin are at most `TIGHT` times
   the positive residual measured against them (`loose`), so neither can be loosened unseen.
12. *Coverage* (proofs/registry.py).  A theorem whose statement is about every height field
   (`COUNTED_PER_FIELD`) has evidence that compared renderer outputs of each registered field
   (`Verdict.covers`), not only enough outputs in all.
"""

from __future__ import annotations

import dataclasses
import functools
import operator
import random
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Callable

import mpmath
import sympy as sp
from sympy.core.function import AppliedUndef

__all__ = ["CITATION", "PLACEHOLDER", "TYPED_RELATION", "placeholder_key", "citations", "plain", "spelled", "listed", "Verdict", "Identity", "Step", "calc", "chains", "Theorem", "variant", "check_identities", "written", "catalogue", "Dot",
           "Cross", "Jacobian", "DIGITS", "POINTS"]

#: Working precision of numerical verification, in significant decimal digits.
DIGITS = 30
#: Number of seeded random points for numerical verification.
POINTS = 24
#: The seed of a step's numerical check (the quick probe draws from SEED + 1000 on).
SEED = 0
#: A residual below 10**(-TOLERANCE_DIGITS) at DIGITS of precision counts as zero.
TOLERANCE_DIGITS = 20
#: A threshold (an evidence's ``bound``, a verified pin) may exceed the residual it holds by at most this
#: factor (rule 11): one loosened by orders of magnitude would pass a defect unseen.
TIGHT = 1000.0


def loose(bound, residual):
    """Why ``bound`` is too loose for the measured ``residual`` (rule 11), or None: it may be at most
    `TIGHT` times a positive residual; a residual of exactly 0 leaves it unjudged (a CPU may round
    that sample exactly)."""
    if bound is not None and residual is not None and residual > 0 and bound > TIGHT * residual:
        return (f"its threshold {bound:.2g} is {bound / residual:.2g} times the residual it measured "
                f"({residual:.2g}), more than {TIGHT:g}: a threshold that loose lets a defect pass; tighten it")
    return None


#: A citation of another theorem in a statement or a step's sentence: ``⟪frame-orthonormal⟫``.
CITATION = re.compile(r"⟪([^⟫]*)⟫")
#: A theorem named by its id in words (rule 8 refuses it): "theorem chart", "Theorems `chart`",
#: "theorem “chart”", any case, any spacing or line break, the id quoted or not.
WORDS_CITATION = re.compile(r"\btheorems?\s+[`'\"“‘]?([\w-]+)", re.IGNORECASE)
#: What a statement prints from the theorem's objects (the book fills it in): ``⟦key⟧``.
PLACEHOLDER = re.compile(r"⟦([^⟧]+)⟧")
#: A relation typed by hand in a statement's mathematics (rule 10 refuses it): =, <, >, the Unicode
#: ones and LaTeX's (``\le``, ``\leqslant``, ``\ne``, ``\to``, ``\in``, ...).
TYPED_RELATION = re.compile(r"[=<>≤≥≠→←⇒⇔∈∉≈≡∼≃≅∝↦⊂⊆⊃⊇≪≫]|\\(?:[lg]eq?(?:slant)?|[lg]t|neq?|to|in|notin|ni|approx|"
                            r"equiv|sim|simeq|cong|propto|mapsto|su[bp]set(?:eq)?|ll|gg|gets|iff|implies|"
                            r"(?:long)?(?:[lL]eft|[rR]ight|[lL]eftright)arrow)(?![a-zA-Z])")
#: A statement's mathematics, in each delimiter MyST takes: ``$...$``, ``$$...$$``, ``\\(...\\)``,
#: ``\\[...\\]`` and the ``{math}`` role; its one non-empty group is the TeX.
MATH = re.compile(r"\$\$(.+?)\$\$|\$(.+?)\$|\\\((.+?)\\\)|\\\[(.+?)\\\]|\{math\}`([^`]+)`", re.DOTALL)


class _Registered(Mapping):
    """id -> title of every theorem of proofs/registry.py (its ``CITABLE``), read when asked: empty
    while that module is not imported (this module imports neither a theorem nor the registry)."""

    def _titles(self):
        registry = sys.modules.get(f"{__package__}.registry")
        return registry.CITABLE if registry is not None else {}

    def __getitem__(self, theorem_id):
        return self._titles()[theorem_id]

    def __contains__(self, theorem_id):
        return theorem_id in self._titles()

    def __iter__(self):
        return iter(self._titles())

    def __len__(self):
        return len(self._titles())


#: id -> title of every theorem that may be cited: proofs/registry.py's, once it is imported; a
#: citation while it is not is refuted, as unknown.
CITABLE = _Registered()


def citations(text) -> list:
    """The theorem ids ``text`` cites (`CITATION`), in order."""
    return CITATION.findall(text)


def citation_cycle(theorems):
    """A cycle among the citations of ``theorems`` (id -> `Theorem`; a statement's or a step's ``⟪id⟫``)
    as the ids around it, the first repeated last (["a", "b", "a"]: a cites b, which cites a), or None."""
    from graphlib import CycleError, TopologicalSorter
    graph = {tid: {c for text in [t.statement] + [s.why for s in t.steps] for c in citations(text)}
             for tid, t in theorems.items()}
    try:
        TopologicalSorter(graph).prepare()
    except CycleError as exc:
        return list(reversed(exc.args[1]))
    return None


def plain(text, titles=None) -> str:
    """``text`` with each citation ``⟪id⟫`` written as ``theorem “title”`` (``titles``: id -> title,
    `CITABLE` by default), for the plain text of a verdict or a ledger; an id
    without a title is left as the marker.  (The book prints "Theorem n (title)".)"""
    titles = CITABLE if titles is None else titles
    return CITATION.sub(lambda m: f"theorem “{titles[m.group(1)]}”" if m.group(1) in titles else m.group(0), text)


def spelled(n) -> str:
    """A count as a statement or an evidence writes it: "three" (fields), 12 from ten on."""
    return ("no", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine")[n] if n < 10 else str(n)


def listed(words) -> str:
    """Words as a sentence lists them: "sine", "sine and ridges", "sine, ridges and rings"."""
    words = list(words)
    return " and ".join([", ".join(words[:-1]), words[-1]] if len(words) > 1 else words)


@dataclass(frozen=True)
class Verdict:
    """Outcome of a check."""

    status: str                   # "proved" | "verified" | "refuted"
    evidence: str                 # one line a reader can check
    residual: float | None = None  # worst |lhs - rhs| found numerically (None if exact)
    digits: int | None = None
    points: int | None = None
    rendered: int = 0              # renderer outputs (pixels, or frames) the check compared
    numeric: tuple = ()            # a theorem's steps (numbers) that sympy left and mpmath verified
    bound: float | None = None     # the threshold evidence held ``residual`` to (rule 11: within TIGHT of it)
    covers: tuple = ()             # the height fields whose renderer outputs the evidence compared (rule 12)

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


def _radicals_reduced(expr):
    """``expr`` with each square root sqrt(S) (and S^(k/2)) written as a new positive symbol r
    (r^k), r^k then reduced to r^(k mod 2) S^(k div 2), expanded: 0 (a sufficient test) when the
    terms cancel with the roots kept whole, as in a normalised vector's derivative, where it takes
    a fraction of a second and ``expand`` seconds."""
    halves = [p for p in expr.atoms(sp.Pow) if p.exp.is_Rational and p.exp.q == 2]
    roots = {sp.expand(p.base): sp.Dummy("r", positive=True) for p in halves}
    if not roots:
        return sp.expand(expr)

    def of_root(p):                       # S^(k/2) and S^k of a root's S, however S is written
        return p.is_Pow and p.exp.is_Rational and p.exp.q <= 2 and not p.base.is_Atom and sp.expand(p.base) in roots
    e = sp.expand(expr.replace(of_root, lambda p: roots[sp.expand(p.base)] ** (2 * p.exp)))
    for base, r in roots.items():
        e = e.replace(lambda x: x.is_Pow and x.base == r and x.exp.is_Integer and x.exp != 1,
                      lambda x: r ** (x.exp % 2) * base ** (x.exp // 2))
    return sp.expand(e)


def _circle_reduced(expr):
    """``expr`` with sin(a) and cos(a) of each argument ±a (expanded) written as new symbols ±s and c,
    over a common denominator, its numerator reduced by s**2 = 1 - c**2 (the remainder of its
    division by s**2 + c**2 - 1 in s), expanded: 0 (a sufficient test) when the numerator vanishes
    on every circle s**2 + c**2 = 1, as a tangent frame's products of sines and cosines do, where
    it takes milliseconds and ``simplify`` a tenth of a second or more.  Arguments that differ
    (a and 2a) stay independent: what needs a double angle is left to ``simplify``."""
    pairs, symbols = {}, {}
    for f in expr.atoms(sp.sin, sp.cos):
        a = sp.expand(f.args[0])
        sign = -1 if a.could_extract_minus_sign() else 1          # sin(-a) = -sin(a), cos(-a) = cos(a)
        s, c = pairs.setdefault(sign * a, (sp.Dummy("s"), sp.Dummy("c")))
        symbols[f] = sign * s if isinstance(f, sp.sin) else c
    numerator = sp.expand(sp.numer(sp.together(expr.xreplace(symbols))))
    for s, c in pairs.values():
        if numerator.has(s):
            numerator = sp.expand(sp.rem(numerator, s**2 + c**2 - 1, s))
    return numerator


def _exactly_zero(expr) -> bool:
    expr = sp.sympify(expr)
    if expr == 0:
        return True
    if _radicals_reduced(expr) == 0:
        return True
    try:
        if _circle_reduced(expr) == 0:
            return True
    except sp.PolynomialError:                  # a sine inside a root or an Abs: not a polynomial in s and c
        pass
    for simplifier in (sp.expand, sp.simplify, lambda e: sp.simplify(sp.expand_trig(e)), sp.trigsimp):
        try:
            if simplifier(expr) == 0:
                return True
        except (TypeError, ValueError, NotImplementedError):  # pragma: no cover - sympy limits
            continue
    return False


class Unevaluable(Exception):
    """An identity's difference raised at a sampled point: the checker cannot decide it there."""

    def __init__(self, label, point, error):
        where = ", ".join(f"{k}={float(v):.6g}" for k, v in point.items())
        super().__init__(f"{label}: cannot be evaluated at {where} ({type(error).__name__}: {error})")


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
            try:
                r = abs(fn(*[point[s] for s in free]))
            except (ArithmeticError, ValueError, TypeError) as e:   # 1/0, log(-1) as a real, ...
                raise Unevaluable(identity.label, point, e) from None
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
    ``points`` seeded points with ``digits`` digits, or refuted.  A component
    that cannot be evaluated at a sampled point (its difference raises there,
    as ``1/floor(x)`` on (0.1, 0.9)) is refuted, the evidence naming it, the
    point and the error: what the checker cannot evaluate it does not pass.
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
    try:
        return _decide_components(components, seed, points, digits)
    except Unevaluable as e:
        return Verdict("refuted", str(e), digits=digits, points=points)


def _decide_components(components, seed, points, digits) -> Verdict:
    tolerance = 10.0 ** (-TOLERANCE_DIGITS)

    def refuted(r, label, at):
        where = ", ".join(f"{k}={float(v):.6g}" for k, v in (at or {}).items())
        return Verdict("refuted", f"{label}: residual {r:.3e}" + (f" at {where}" if where else ", a constant"),
                       residual=r, digits=digits, points=points)

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


# ------------------------------------------------------------------- notation that evaluates
def _explicit(x):
    """``x`` evaluated: written forms unwrapped, ``doit`` (derivatives, limits, `Dot`, ...), matrices explicit."""
    x = x.replace(lambda e: isinstance(e, sp.UnevaluatedExpr), lambda e: e.args[0]).doit()
    return _dense(x)


def _dense(x):
    """A matrix expression as an explicit matrix, its sums and products formed from explicit
    factors (``as_explicit`` of a product writes each entry as a ``Sum`` over an index and hands
    it to sympy's summation, which is many times slower); scalars and explicit matrices pass through."""
    if isinstance(x, (sp.MatMul, sp.MatAdd)):
        return functools.reduce(operator.mul if isinstance(x, sp.MatMul) else operator.add, map(_dense, x.args))
    return x.as_explicit() if isinstance(x, sp.MatrixExpr) else x


def _concrete(x, **hints):
    """``x.doit()``, and an explicit matrix where it is a matrix expression of explicit matrices
    (sympy leaves 2 * Matrix(...) a MatMul); a named vector stays a name."""
    x = x.doit(**hints)
    if isinstance(x, sp.MatrixExpr) and not x.atoms(sp.MatrixSymbol) and not x.has(Cross, Jacobian):
        return _dense(x)
    return x


class Dot(sp.Expr):
    """a . b of two 3-vectors: prints ``a \\cdot b``; ``doit`` gives the scalar once both are explicit."""

    is_commutative = True

    def __new__(cls, a, b):
        return sp.Expr.__new__(cls, sp.sympify(a), sp.sympify(b))

    def doit(self, **hints):
        a, b = (_concrete(x, **hints) for x in self.args)
        if isinstance(a, sp.MatrixBase) and isinstance(b, sp.MatrixBase):
            return sp.Matrix(a).dot(sp.Matrix(b))
        return Dot(a, b)



class Cross(sp.MatrixExpr):
    """a x b of two 3-vectors: prints ``a \\times b``; ``doit`` gives the 3-vector once both are explicit."""

    def __new__(cls, a, b):
        return sp.Basic.__new__(cls, sp.sympify(a), sp.sympify(b))

    @property
    def shape(self):
        return (3, 1)

    def doit(self, **hints):
        a, b = (_concrete(x, **hints) for x in self.args)
        if isinstance(a, sp.MatrixBase) and isinstance(b, sp.MatrixBase):
            return sp.ImmutableMatrix(sp.Matrix(a).cross(sp.Matrix(b)))
        return Cross(a, b)



class Jacobian(sp.MatrixExpr):
    """The Jacobian d(f_1..f_m)/d(x_1..x_n) (an m x n matrix): prints
    ``\\partial(f_1, ..)/\\partial(x_1, ..)``; ``doit`` differentiates."""

    def __new__(cls, fs, xs):
        return sp.Basic.__new__(cls, sp.Tuple(*fs), sp.Tuple(*xs))

    @property
    def shape(self):
        return (len(self.args[0]), len(self.args[1]))

    def doit(self, **hints):
        fs, xs = self.args
        return sp.ImmutableMatrix(sp.Matrix([f.doit(**hints) for f in fs]).jacobian(list(xs)))



# ------------------------------------------------------------------------------- written forms
def written(expr):
    """``expr`` (built with ``evaluate=False``) kept as written: printed in the order written
    (``3 u |h|``, not sympy's ``3 |h| u``; but sympy's printer still puts a derivative last: h_u s
    prints as s h_u), evaluated when checked."""
    return sp.UnevaluatedExpr(expr)


# ----------------------------------------------------------------------------- the proofs
@dataclass(frozen=True)
class Step:
    """One step of a proof: ``why`` (one sentence) and the equation ``lhs = rhs``.

    ``link``: the step continues the previous one (a calc chain): its ``lhs`` must be
    the previous step's ``rhs``, and the book shows ``= rhs``.  ``defines``: named
    symbols (keys of the theorem's ``where``) whose definitions the book prints with
    the step.  ``using``: numbers of earlier steps whose left side is a name (or a tuple
    of names): the step is checked with each name replaced by what that step proved it
    equal to, as Lean's ``rw`` (a quantity sympy would otherwise recompute from scratch).
    ``cases``: (label, substitutions) pairs; the step must hold under each
    (a statement about every height field, say), with undefined functions replaced by
    Lambdas and symbols by expressions.  ``domain``, ``functions``: sampling intervals
    and instances of undefined functions for the numerical fallback (`Identity`),
    where they differ from the theorem's.

    The right side may end in ``+ O(x**n)``: the step then holds when the series of lhs - rhs
    about the Order's point vanishes below that order (rule 4 of the module's docstring).

    ``why_numeric``: why sympy does not reduce the step to 0, for a step it leaves to the numerical
    check (`Verdict.numeric`); the book prints it in the theorem's box, and refuses a box of a
    numerically verified step without it.
    """

    why: str
    lhs: object
    rhs: object
    link: bool = False
    defines: tuple = ()
    using: tuple = ()
    cases: tuple = ()
    domain: dict | None = None
    functions: dict | None = None
    why_numeric: str = ""


def calc(lhs, *links, **options):
    """A calc chain ``lhs = r_1 = r_2 = ...``: ``links`` are (why, r_k) pairs, or (why, r_k,
    {Step options}) triples; each step after the first continues the one before
    (`Step.link`).  ``options`` (`Step` fields) apply to every step.  Returns a tuple of `Step`."""
    steps = []
    for why, rhs, *own in links:
        steps.append(Step(why, lhs, rhs, link=bool(steps), **{**options, **(own[0] if own else {})}))
        lhs = rhs
    return tuple(steps)


@dataclass(frozen=True)
class Theorem:
    """A theorem of the chapter.

    Attributes
    ----------
    id : str            stable identifier (cited by the book and verify/)
    title : str
    statement : str     MyST with LaTeX; ``⟦key⟧`` is printed by the book (book/chapter/latex.py):
                        ``claims[key]`` as lhs = rhs, the named symbol whose name is ``key`` as
                        name = definition (``where``), or ``shown[key]`` as itself
    steps : tuple       the proof, `Step` objects in order
    claims : dict       key -> (lhs, rhs): the equations the statement makes; each must be the
                        two ends of a run of one calc chain of ``steps``
    wrong_variants : tuple of (description, callable () -> Verdict); each must be refuted
    where : dict        named symbol (Symbol, MatrixSymbol or undefined function) -> its
                        definition, substituted before a step is checked
    names : dict        symbol -> LaTeX, for symbols whose name is not their notation
    shown : dict        key -> sympy object the statement shows as ``⟦key⟧`` (a vector, a constant)
    domain : dict       symbol -> (lo, hi): sampling intervals for the steps
    functions : dict    undefined function -> Lambda, substituted only for sampling
    evidence : callable () -> Verdict, or None: the renderer's outputs (or code) against the
                        statement; its status is "verified" where the theorem rests on it,
                        "proved" where it is a gate that passed
    """

    id: str
    title: str
    statement: str
    steps: tuple
    claims: dict
    wrong_variants: tuple = ()
    where: dict = field(default_factory=dict)
    names: dict = field(default_factory=dict)
    shown: dict = field(default_factory=dict)
    domain: dict = field(default_factory=dict)
    functions: dict = field(default_factory=dict)
    evidence: Callable[[], Verdict] | None = None

    def check(self) -> Verdict:
        """Every link, every step on its own, every claim reached, then the evidence: the
        first failure refutes, naming the theorem and the step (number and sentence) or claim."""
        return _prove(self)

    def explicit(self, x):
        """``x`` (an expression in the theorem's names) with its ``where`` substituted to the
        renderer's symbols and evaluated: written forms unwrapped, matrices explicit."""
        return _explicit(_substitute(x, self.where))

    def placeholders(self) -> list:
        """The keys of the statement's ``⟦key⟧`` placeholders, in order."""
        return PLACEHOLDER.findall(self.statement)


def placeholder_key(s):
    """The key ``⟦key⟧`` names a named symbol by: its name, or its function's (E for E(x))."""
    return s.func.__name__ if isinstance(s, AppliedUndef) else getattr(s, "__name__", None) or str(s)


def catalogue(titles, builders, key=tuple):
    """``titles()`` and ``build(id)`` of a theorem module, as proofs/registry.py reads them: ``titles``
    ({id: title}, in the chapter's order) and, for each id, its builder (function () -> Theorem) in
    ``builders``; ``build`` calls a builder once per value of ``key()`` (the registered fields, for a
    theorem built from them), then returns the same Theorem, until ``build.cache_clear()``."""
    built = functools.lru_cache(maxsize=None)(lambda theorem_id, _: builders[theorem_id]())

    def build(theorem_id):
        return built(theorem_id, key())
    build.cache_clear = built.cache_clear
    return (lambda: titles), build


def variant(theorem, **changes):
    """A wrong variant's check: ``theorem`` with ``changes`` (fields of `Theorem`), checked when called."""
    from dataclasses import replace
    return lambda: replace(theorem, **changes).check()


def _basic(x):
    x = sp.sympify(x)
    return sp.ImmutableMatrix(x) if isinstance(x, sp.MatrixBase) else x


def _substitute(x, where):
    """``x`` with named symbols (xreplace) and undefined functions (subs) replaced, to a fixed point."""
    symbols = {k: _basic(v) for k, v in where.items() if not isinstance(k, sp.FunctionClass)}
    functions = {k: v for k, v in where.items() if isinstance(k, sp.FunctionClass)}
    x = _basic(x)
    for _ in range(8):
        y = x.xreplace(symbols)
        if functions:
            y = y.subs(functions)
        if y == x:
            return x
        x = y
    return x


def _value(x):
    """``x`` (named symbols already substituted) evaluated (``doit``), as the checker compares
    it: a column Matrix for a vector or a tuple of them, a scalar for a 1 x 1."""
    x = _explicit(x)
    if isinstance(x, sp.Tuple):
        parts = [_explicit(e) for e in x]
        x = sp.Matrix.vstack(*[sp.Matrix(e) if isinstance(e, sp.MatrixBase) else sp.Matrix([e]) for e in parts])
    if isinstance(x, sp.MatrixBase):
        x = sp.Matrix(x)
        return x[0] if x.shape == (1, 1) else x
    return x


def _below_order(lhs, rhs):
    """For ``rhs`` ending in ``+ O((x - x0)**n)`` (`_series_refusal` has admitted it): the series of
    lhs - (rhs without its O) about x0 through (x - x0)**(n - 1) (an expression that must vanish); else None."""
    orders = list(rhs.atoms(sp.Order)) if isinstance(rhs, sp.Expr) else []
    if not orders:
        return None
    (order,) = orders
    var, point = order.variables[0], order.point[0]
    return sp.series(lhs - rhs.removeO(), var, point, sp.degree(order.expr, var)).removeO()


def _terms(x):
    """The terms of ``x``'s sum as written: through `written` and unevaluated sums."""
    if isinstance(x, sp.UnevaluatedExpr):
        return _terms(x.args[0])
    return [t for a in x.args for t in _terms(a)] if isinstance(x, sp.Add) else [x]


def _series_refusal(lhs, rhs):
    """Why a step's sides break rule 4 (an O-term only as a term of the right side's sum, one, in one
    variable about a finite point, containing no written term), or None."""
    def orders(x):
        return x.atoms(sp.Order) if isinstance(x, sp.Basic) else set()
    if orders(lhs):
        return "its left side carries an O-term; only a right side may end in + O(x**n)"
    found = orders(rhs)
    if not found:
        return None
    terms = _terms(rhs)
    order = next(iter(found))
    if len(found) > 1 or order not in terms:
        return f"its right side must end in one O-term, a term of its sum: it has {sorted(map(str, found))}"
    var, point = order.variables[0], order.point[0]
    n = sp.degree(order.expr, var) if len(order.variables) == 1 and order.expr.is_polynomial(var) else None
    if n is None or n < 1 or order.expr != (var - point) ** n:         # x0 infinite: (x - oo)**n is no power of x
        return f"its O-term {order} is not O((x - x0)**n) in one variable x about a finite point x0, n >= 1"
    inside = [t for t in terms if t != order and order.contains(t) is True]
    if inside:
        return (f"it writes {', '.join(map(str, inside))} inside {order}, which would absorb "
                f"{'them' if len(inside) > 1 else 'it'}: state the series to a higher order or drop the term")
    return None


#: Verdicts of the equations already decided in this process: a theorem, its wrong variants
#: and the tests that plant a wrong step share most of their steps (`pytest verify`: 121 s
#: without it, 78 s with it, on 2 cores).
_DECIDED = {}


def _decide(theorem, step, lhs, rhs, rewrites=None):
    """`check_identities` on lhs = rhs, with ``rewrites`` (name -> what an earlier step proved) and the
    theorem's named symbols substituted, in every case of ``step.cases`` (or once), at `SEED`,
    `POINTS` and `DIGITS`.  The verdict's evidence names the case that fails."""
    domain = theorem.domain if step.domain is None else step.domain
    functions = theorem.functions if step.functions is None else step.functions
    numbers = dict(seed=SEED, points=POINTS, digits=DIGITS)
    verdicts = []
    for label, case in step.cases or (("", {}),):
        where = {**theorem.where, **(rewrites or {}), **case}
        a, b = _substitute(lhs, where), _substitute(rhs, where)
        key = (a, b, frozenset(domain.items()), frozenset(functions.items()), tuple(numbers.items()),
               TOLERANCE_DIGITS)
        if key not in _DECIDED:
            a, b = _value(a), _value(b)
            series = _below_order(a, b)
            if series is not None:
                a, b = series, sp.Integer(0)
            _DECIDED[key] = check_identities([Identity("", a, b, domain, functions)], **numbers)
        v = _DECIDED[key]
        if not v.holds:      # "[k]: residual ..." of a vector's component k, ": residual ..." of a scalar
            where_ = re.sub(r"^\[(\d+)\]: ", r"component \1: ", v.evidence).removeprefix(": ")
            return dataclasses.replace(v, evidence=(f"in case {label}, " if label else "") + where_)
        verdicts.append(v)
    return max(verdicts, key=lambda v: (v.status == "verified", v.residual or 0.0))


def chains(steps):
    """[first, last] step indices (0-based) of each maximal calc chain of ``steps``: a run of a
    step and the links (`Step.link`) after it."""
    runs = []
    for k, s in enumerate(steps):
        if s.link and runs:
            runs[-1][1] = k
        else:
            runs.append([k, k])
    return runs


def _reaches(steps, lhs, rhs):
    """Whether a run a..b of one chain goes from ``lhs`` (step a's left side) to ``rhs`` (step b's right)."""
    return any(steps[a].lhs == lhs and steps[b].rhs == rhs
               for first, last in chains(steps) for a in range(first, last + 1) for b in range(a, last + 1))


def _rewrites(t, k, step):
    """{name: proved value} of the earlier steps ``step.using`` names, or a str saying why not."""
    out = {}
    for j in step.using:
        if not (isinstance(j, int) and not isinstance(j, bool) and 1 <= j < k):
            return f"uses step {j}, which does not come before it"
        lhs, rhs = t.steps[j - 1].lhs, t.steps[j - 1].rhs
        pairs = zip(lhs, rhs) if isinstance(lhs, sp.Tuple) and isinstance(rhs, sp.Tuple) and len(lhs) == len(rhs) \
            else [(lhs, rhs)]
        for name, value in pairs:
            if not isinstance(name, (sp.Symbol, sp.MatrixSymbol, AppliedUndef)):
                return f"uses step {j}, whose left side is not a name"
            out[name] = value
    # A citation the step never reaches (its sides, through the theorem's other definitions) is refused:
    # it would tell the reader the step rests on a step it does not use.
    if not step.using:
        return out
    others = {n: v for n, v in t.where.items() if n not in out}
    sides = [_substitute(x, others) for x in (step.lhs, step.rhs, *([t.steps[k - 2].rhs] if step.link else []))]
    for j in step.using:
        lhs = t.steps[j - 1].lhs
        if not any(x.has(name) for name in (lhs if isinstance(lhs, sp.Tuple) else [lhs]) for x in sides):
            return f"uses step {j}, whose left side {lhs} it does not contain"
    return out


def _unknown_citation(t):
    """Why ``t`` breaks rule 8 (a citation ``⟪id⟫`` of an id the registry does not hold), or None."""
    for where, text in [("its statement", t.statement)] + [(f"step {k}", s.why) for k, s in enumerate(t.steps, 1)]:
        unknown = [i for i in citations(text) if i not in CITABLE]
        if unknown:
            return (f"{t.id}: {where} cites ⟪{unknown[0]}⟫, which is no theorem of the registry"
                    + ("" if CITABLE else " (proofs.registry, whose theorems proofs.core.CITABLE reads, is not imported)"))
        for m in WORDS_CITATION.finditer(text):
            if m.group(1) in CITABLE:
                return f"{t.id}: {where} names theorem {m.group(1)} by its id in words: cite it as ⟪{m.group(1)}⟫"
    return None


def _unknown_placeholder(t):
    """Why ``t`` breaks rule 10 (a statement's ``⟦key⟧`` that names no claim, named symbol or
    shown object), or None."""
    known = set(t.claims) | {placeholder_key(s) for s in t.where} | set(t.shown)
    unknown = [k for k in t.placeholders() if k not in known]
    if unknown:
        return (f"{t.id}: its statement shows ⟦{unknown[0]}⟧, which is neither a claim {sorted(t.claims)}, a named "
                f"symbol {sorted(placeholder_key(s) for s in t.where)} nor a shown object {sorted(t.shown)}")
    for m in MATH.finditer(t.statement):
        typed = TYPED_RELATION.search(PLACEHOLDER.sub("", next(g for g in m.groups() if g is not None)))
        if typed:
            return (f"{t.id}: its statement types the relation {typed.group(0)!r} by hand in {m.group(0)!r}: show it "
                    "through ⟦key⟧, from a claim, a named symbol of where or an object of shown")
    return None


def _prove(t: Theorem) -> Verdict:
    unknown = _unknown_citation(t)
    if unknown:
        return Verdict("refuted", unknown)
    decided = []                   # (step number, verdict) of every step and link
    for k, step in enumerate(t.steps, 1):
        name = f"{t.id}, step {k} ({plain(step.why).rstrip('.:')})"
        rewrites = _rewrites(t, k, step)
        if isinstance(rewrites, str):
            return Verdict("refuted", f"{name} {rewrites}")
        series = _series_refusal(step.lhs, step.rhs)
        if series is not None:
            return Verdict("refuted", f"{name}: {series}")
        if step.link:
            if k == 1:
                return Verdict("refuted", f"{name}: continues a step that does not exist")
            before = t.steps[k - 2].rhs
            if step.lhs != before:
                v = _decide(t, step, before, step.lhs, rewrites)
                if not v.holds:
                    return Verdict("refuted", f"{name} does not continue step {k - 1}: its left side differs "
                                   f"from step {k - 1}'s right side, {v.evidence}", v.residual, v.digits, v.points)
                decided.append((k, v))
        v = _decide(t, step, step.lhs, step.rhs, rewrites)
        if not v.holds:
            return Verdict("refuted", f"{name}: {v.evidence}", v.residual, v.digits, v.points)
        decided.append((k, v))
    for key, (lhs, rhs) in t.claims.items():
        if not _reaches(t.steps, lhs, rhs):
            return Verdict("refuted", f"{t.id}: no chain of steps runs from the left side of the claim {key!r} "
                           "to its right side: the proof does not reach the statement")
    unknown = _unknown_placeholder(t)
    if unknown:
        return Verdict("refuted", unknown)
    numeric = sorted({k for k, v in decided if v.status == "verified"})
    worst = max((v.residual for _, v in decided if v.status == "verified"), default=None)
    summary = (f"{len(t.steps)} steps, each reduced to 0 by sympy" if not numeric else
               f"{len(t.steps)} steps, reduced to 0 by sympy but for step{'s' if len(numeric) > 1 else ''} "
               f"{', '.join(map(str, numeric))}, which hold{'' if len(numeric) > 1 else 's'} numerically (worst "
               f"residual {worst:.1e} at {POINTS} seeded points, {DIGITS} digits)")
    residual, digits, points = (worst, DIGITS, POINTS) if numeric else (None, None, None)
    numeric = tuple(numeric)
    if t.evidence is None:
        return Verdict("verified" if numeric else "proved", summary, residual, digits, points, numeric=numeric)
    e = t.evidence()
    if not isinstance(e, Verdict):
        return Verdict("refuted", f"{t.id}: its evidence returned {e!r:.80}, not a Verdict")
    if not e.holds:
        return e if e.status == "refuted" else dataclasses.replace(e, status="refuted")
    too_loose = loose(e.bound, e.residual)
    if too_loose:
        return Verdict("refuted", f"{t.id}: its evidence's {too_loose}", e.residual)
    if e.status == "verified" and not (e.residual is not None and 0 <= e.residual < float("inf") and e.points):
        return Verdict("refuted", f"{t.id}: its evidence is verified but states no finite residual and points "
                       f"(residual {e.residual}, points {e.points}): {e.evidence}")
    if e.status == "verified" and not numeric:
        residual, digits, points = e.residual, e.digits, e.points
    status = "verified" if numeric or e.status == "verified" else "proved"
    return Verdict(status, f"{summary}; {e.evidence}", residual, digits, points, e.rendered, numeric,
                   covers=e.covers)
