"""How a pixel is shaded: ambient, Lambert and a Blinn or Phong highlight (seed Cell 1, ``shade1``).

The kernel writes its shading by hand (`renderer.kernel.light_term` and `shade_lit`; the
simulator's renderer/js/render.js the same), as it writes the hit and the shadow test.  This
theorem states what it computes, proves the two facts its code rests on (the Phong cosine it
evaluates, 2 (N'.w_i)(N'.w_o) - w_i.w_o, is the cosine of the mirror direction; Blinn's half
vector bisects w_i and w_o), and earns the statement on the renderer's own pixels: seeded pixels
of spheres A and B and of the floor (its checker and tint included) in the chapter's scene (Blinn,
the seed's shininess 32) and a Phong scene whose lights and materials are drawn at random, their
rendered colour against the statement's formula evaluated by mpmath at `proofs.core.DIGITS` digits,
fed the renderer's hit point P and shading normal N' and the lights its reach predicate lets through
(`renderer.pointwise.reach`, which theorem ``no-boundary`` holds to the shadow predicates).
"""

from functools import partial

import mpmath
import numpy as np
import sympy as sp

from .core import DIGITS, Dot, Step, Theorem, Verdict, _explicit, catalogue, written

#: The vectors the statement names: the shading normal, the unit vectors to the light and to the eye,
#: the light's mirror direction in N' (Phong) and the half vector (Blinn), in pbrt-v4's omega notation.
NP, WI, WO, WR, HV = (sp.MatrixSymbol(name, 3, 1) for name in ("N'", "omega_i", "omega_o", "omega_r", "omega_h"))
#: The weights, the shininess nu, the albedo, the ambient light, a light's colour and the pixel's colour I
#: (each one channel); the letters the book's other formulas use for other things are avoided.
k_a, k_d, k_s, nu, rho, I_a, I_l, I = sp.symbols("k_a k_d k_s nu rho I_a I_ell I", nonnegative=True)
#: The highlight's cosine: real, not nonnegative (sympy would drop the clamp max(0, s)); and its clamp to
#: [0, 1], a name the statement prints and defines (`CLAMP`).
s = sp.Symbol("mu", real=True)
S_PLUS = sp.Symbol("mu_+", nonnegative=True)
CLAMP = {S_PLUS: sp.Min(1, sp.Max(0, s))}
ell, m = sp.symbols("ell n_ell", integer=True, positive=True)   # a light, and their count
T = sp.IndexedBase("T")
#: The floor's albedo: P = (x, y, 0) on it, c the checker's grey at P (`checker`) and tau the tint.
X, Y = sp.symbols("x y", real=True)
tau, c = sp.symbols("tau c", nonnegative=True)
FLOOR = sp.Tuple((1 - tau) * c, (1 - tau) * c, c)
NAMES = {NP: "N'", WI: r"\omega_i", WO: r"\omega_o", WR: r"\omega_r", HV: r"\omega_h", rho: r"\rho", I_l: r"I_\ell",
         ell: r"\ell", m: r"n_\ell", s: r"\mu", S_PLUS: r"\mu_+", tau: r"\tau"}
#: The scene's parameter (`renderer.Scene`) each symbol stands for, for the book's list of them.
SCENE_SYMBOLS = {"lights": I_l, "ambient": I_a, "albedo_a": rho, "albedo_b": rho, "ka": k_a, "kd": k_d, "ks": k_s,
                 "shininess": nu, "floor_tint": tau}

#: |w_i + w_o|, a name the statement prints, defined in the theorem's ``where`` (`LENGTH`).
NORM = sp.Symbol("|omega_i + omega_o|", positive=True)
NAMES[NORM] = r"\lVert\omega_i + \omega_o\rVert"
LENGTH = {NORM: sp.sqrt(Dot(WI + WO, WI + WO))}
MIRROR = 2 * Dot(NP, WI) * NP - WI
HALF = (WI + WO) / NORM
#: The Phong cosine as the kernel evaluates it (`renderer.kernel.specular_axis`): no mirror vector formed.
KERNEL_PHONG = 2 * Dot(NP, WI) * Dot(NP, WO) - Dot(WI, WO)
#: One light's term where N' . w_i > 0 (nothing elsewhere), and the colour of a channel.
TERM = I_l * (k_d * rho * Dot(NP, WI) + k_s * S_PLUS ** nu)
COLOUR = sp.Min(1, written(sp.Add(sp.Mul(k_a, I_a, evaluate=False), sp.Sum(T[ell], (ell, 1, m)), evaluate=False)))
#: The specular cosine s of each model, as the renderer evaluates it.
COSINE = {"blinn": Dot(NP, HALF), "phong": KERNEL_PHONG}

#: Unit vectors in angles, for the steps that hold for unit vectors only.
_ANGLES = sp.symbols("alpha_1:4 gamma_1:4", real=True)


def _unit(alpha, gamma):
    return sp.ImmutableMatrix([sp.sin(alpha) * sp.cos(gamma), sp.sin(alpha) * sp.sin(gamma), sp.cos(alpha)])


UNIT = {vec: _unit(_ANGLES[k], _ANGLES[3 + k]) for k, vec in enumerate((NP, WI, WO))}
DOMAIN = {**{x: (0.05, 3.1) for x in _ANGLES[:3]}, **{x: (-3.1, 3.1) for x in _ANGLES[3:]}}

#: The scenes of the evidence: the book's (Blinn at the seed's shininess 32: repeated squaring in the
#: kernel), and Phong with every shading parameter drawn at random (seeded): coloured lights, ambient and
#: albedos whose channels all differ, and a fractional shininess (libm's pow).
def _scenes(seed=0):
    from renderer.scene import PointLight, Scene
    rng = np.random.default_rng(seed)
    colour = lambda: tuple(rng.uniform(0.1, 1.0, 3))                      # noqa: E731
    lights = tuple(PointLight(light.position, colour()) for light in Scene().lights)   # the book's, recoloured
    drawn = dict(ka=rng.uniform(0.1, 0.5), kd=rng.uniform(0.3, 1.0), ks=rng.uniform(0.2, 1.0),
                 shininess=rng.uniform(2.0, 40.0), ambient=colour(), albedo_a=colour(), albedo_b=colour())
    return ({}, dict(model="phong", lights=lights, height_field="sine", bump="chart", floor_tint=rng.uniform(0, 1),
                     **drawn))


def greys():
    """The renderer's greys of the floor's light and dark squares (`renderer.kernel.FLOOR_LIGHT`, ``FLOOR_DARK``)."""
    from renderer.kernel import FLOOR_DARK, FLOOR_LIGHT
    return FLOOR_LIGHT, FLOOR_DARK


def checker(light=None, dark=None):
    """The floor's grey c at P = (x, y, 0): ``light`` where sin(pi x) sin(pi y) >= 0, ``dark`` elsewhere (unit
    squares; seed Cell 1); by default the renderer's (`greys`)."""
    if light is None:
        light, dark = greys()
    return sp.Piecewise((sp.Float(light, 15), sp.sin(sp.pi * X) * sp.sin(sp.pi * Y) >= 0), (sp.Float(dark, 15), True))


#: Odd: the middle column's pixel centres have x = 0 exactly, where the checker's sin(pi x) sin(pi y) is 0 and
#: the statement says light (its >=), so the evidence holds the floor to the statement on that boundary too.
SIZE = 129
#: Pixels compared per scene, at most: from sphere A, from sphere B and from the floor.
PER_CHAMBER = (200, 100, 150)
#: A pixel whose N' . w_i lies within this of 0 for a light that reaches it is left out: the statement's
#: term jumps there (the highlight is cut where the light goes behind N'), and rounding decides the side;
#: so is a floor pixel whose sin(pi x) sin(pi y) does, where the checker changes grey, unless it is exactly 0 (there
#: the kernel and mpmath both compute 0, and every such pixel is compared).
GATE_MARGIN = 1e-9
#: Absolute tolerance on a colour in [0, 1], about 1000 unit roundoffs: the kernel's unit vectors and
#: cosines carry a few each, and the power n multiplies the cosine's relative rounding by n (up to 40 here).
TOLERANCE = 2.0**-43


def _formula_colour(scene, term, gate=True, colour_of=COLOUR):
    """A function of float64 rows (P, N', rho, V_1..V_m) (k, 9 + m) of ``scene``'s pixels: the colour
    (k, 3) that ``colour_of`` (`COLOUR`) with one ``term`` per light gives there, evaluated by mpmath at `DIGITS`
    digits in two stages (each light's N' . w_i and s from P and N', then the colour from those), so that
    sympy never builds a min or max of the long expressions."""
    P = sp.Matrix(sp.symbols("P_x P_y P_z", real=True))
    Ns = sp.Matrix(sp.symbols("n_x n_y n_z", real=True))
    eye = sp.Matrix([0, 0, scene.camera_z]) - P
    geometry = []
    for light in scene.lights:
        to_light = sp.Matrix(light.position) - P
        at = {NP: Ns, WI: to_light / sp.sqrt(to_light.dot(to_light)), WO: eye / sp.sqrt(eye.dot(eye))}
        geometry += [_explicit(x.xreplace(LENGTH).xreplace(at)) for x in (Dot(NP, WI), COSINE[scene.model])]
    geometry = sp.lambdify(tuple(P) + tuple(Ns), geometry, modules="mpmath", cse=True)
    albedo = sp.symbols("rho_r rho_g rho_b", nonnegative=True)
    cosines = sp.symbols(f"mu_1:{len(scene.lights) + 1}", real=True)
    highlights = sp.symbols(f"s_1:{len(scene.lights) + 1}", real=True)
    reach = sp.symbols(f"V_1:{len(scene.lights) + 1}", nonnegative=True)
    colour = []
    for ch in range(3):
        # The scene's values of the statement's symbols (`SCENE_SYMBOLS`) in this channel; rho is the pixel's.
        values = {sym: getattr(scene, name)[ch] if isinstance(getattr(scene, name), tuple) else getattr(scene, name)
                  for name, sym in SCENE_SYMBOLS.items() if sym not in (rho, I_l)}
        terms = []
        for light, mu, s_l, v in zip(scene.lights, cosines, highlights, reach):
            lit = term.xreplace(CLAMP).xreplace({Dot(NP, WI): mu, s: s_l, I_l: light.color[ch]})
            terms.append(v * (sp.Piecewise((lit, mu > 0), (0, True)) if gate else lit))
        total = colour_of.replace(lambda e: isinstance(e, sp.Sum), lambda e: sp.Add(*terms))
        colour.append(_explicit(total).xreplace({**values, rho: albedo[ch]}))
    colour = sp.lambdify(sum(zip(cosines, highlights), ()) + albedo + reach, colour, modules="mpmath")

    def evaluate(rows):
        out = np.empty((rows.shape[0], 3))
        with mpmath.workdps(DIGITS):
            for i, row in enumerate(rows):
                x = [mpmath.mpf(float(value)) for value in row]
                out[i] = [float(value) for value in colour(*geometry(*x[:6]), *x[6:])]
        return out
    return evaluate


def _floor_albedo(floor, grey, tint, P):
    """The albedo (k, 3) that ``floor`` (`FLOOR`) with c = ``grey`` (`checker`) and tau = ``tint`` gives at the
    floor points ``P`` (k, 3), by mpmath at `DIGITS` digits."""
    at = sp.lambdify((X, Y), floor.xreplace({c: grey, tau: tint}), modules="mpmath")
    with mpmath.workdps(DIGITS):
        return np.array([[float(x) for x in at(mpmath.mpf(float(px)), mpmath.mpf(float(py)))] for px, py, _ in P])


def _evidence(term=TERM, normal="Ns", gate=True, shadows=True, colour_of=COLOUR, floor=FLOOR, grey=None,
              unbumped=("sphere B", "floor")):
    """The rendered colour at seeded pixels of `_scenes` (spheres A and B, the floor) against the statement,
    after checking that the chambers ``unbumped`` (`renderer.CHAMBER_NAMES`' names) have N' = N at every
    pixel, and the floor N = (0, 0, 1).  Wrong variants: ``term``, ``colour_of``, ``floor``, ``grey``
    (`checker`'s), ``unbumped``; ``normal``, the G-buffer's normal fed as N' ("Ns", or "N" the unbumped one);
    ``gate`` False, the term kept where N' . w_i <= 0; ``shadows`` False, the lights that reach P decided
    without sphere B."""
    from renderer import CHAMBER_NAMES, Scene, gbuffer, pointwise, render
    from renderer.render import FLOOR as ON_FLOOR, SPHERE_A, SPHERE_B
    grey = checker() if grey is None else grey
    worst, count, rng = 0.0, 0, np.random.default_rng(0)
    for options in _scenes():
        scene = Scene(**options)
        g, image = gbuffer(scene, SIZE, SIZE), render(scene, SIZE, SIZE).image
        flat = np.isin(g.chamber, [code for code, name in CHAMBER_NAMES.items() if name in unbumped])
        bumped = (flat & np.any(g.Ns != g.N, axis=-1)
                  | (g.chamber == ON_FLOOR) & np.any(g.N != (0.0, 0.0, 1.0), axis=-1))
        if bumped.any():
            return Verdict("refuted", f"{int(bumped.sum()):,} pixels of {' or '.join(unbumped)} have N' other than N, "
                           "or a floor N other than (0, 0, 1)")
        reach = pointwise.reach(scene if shadows else scene.replace(sphere_b=False), g)      # (lights, H, W)
        fed = getattr(g, normal)
        to_light = np.stack([np.asarray(l.position) - g.P for l in scene.lights])
        mu = np.einsum("hwk,lhwk->lhw", g.Ns, to_light) / np.linalg.norm(to_light, axis=-1)
        squares = np.sin(np.pi * g.P[..., 0]) * np.sin(np.pi * g.P[..., 1])
        clear = (~np.any(reach & (np.abs(mu) < GATE_MARGIN), axis=0)
                 & ((g.chamber != ON_FLOOR) | (abs(squares) > GATE_MARGIN) | (squares == 0)))
        rows, want = [], []
        for code, most in zip((SPHERE_A, SPHERE_B, ON_FLOOR), PER_CHAMBER):
            edge = np.flatnonzero((g.chamber == code) & (squares == 0)) if code == ON_FLOOR else np.zeros(0, int)
            idx = np.setdiff1d(np.flatnonzero((g.chamber == code) & clear), edge)
            take = np.concatenate([edge, rng.choice(idx, size=min(most - edge.size, idx.size), replace=False)])
            P = g.P.reshape(-1, 3)[take]
            albedo = (_floor_albedo(floor, grey, scene.floor_tint, P) if code == ON_FLOOR else
                      np.tile(scene.albedo_a if code == SPHERE_A else scene.albedo_b, (take.size, 1)))
            rows.append(np.hstack([P, fed.reshape(-1, 3)[take], albedo, reach.reshape(len(scene.lights), -1)[:, take].T]))
            want.append(image.reshape(-1, 3)[take])
        rows, want = np.vstack(rows), np.vstack(want)
        worst = max(worst, float(np.max(np.abs(_formula_colour(scene, term, gate, colour_of)(rows) - want))))
        count += rows.shape[0]
    if worst > TOLERANCE:
        return Verdict("refuted", f"the rendered colour differs from the shading formula by {worst:.1e} at some of "
                       f"{count:,} pixels of the spheres and the floor")
    return Verdict("proved", f"{count:,} seeded pixels of the spheres and the floor (the chapter's scene, Blinn; Phong with "
                   f"random lights, materials and tint) within {worst:.1e} of the formula in mpmath, from the "
                   f"renderer's P, N' and reach",
                   residual=worst, rendered=count, bound=TOLERANCE)


def _theorem(phong=KERNEL_PHONG, mirror=MIRROR, half=HALF, **evidence):
    """Theorem shading, claiming the kernel's Phong cosine ``phong``, for the mirror direction ``mirror``
    and half vector ``half``, and `_evidence`'s options (wrong variants)."""
    reflects = (sp.Tuple(Dot(NP, WR), Dot(WR, WR)), sp.Tuple(Dot(NP, WI), 1))
    bisects = (sp.Tuple(Dot(HV, WI) - Dot(HV, WO), Dot(HV, HV)), sp.Tuple(0, 1))
    return Theorem(
        id="shading", title=TITLES["shading"],
        statement=(
            r"At a hit point $P$, with unbumped normal $N$ (a sphere's outward unit normal), shading normal $N'$ "
            r"(on sphere A the perturbed normal that §3 derives, on sphere B its $N$), $\omega_o$ the unit "
            r"vector to the eye, and for each of the scene's $n_\ell$ lights $\omega_i$ (incident) the unit vector to it "
            r"and $I_\ell$ its colour, the renderer's colour (each of red, green, blue) is $$⟦colour⟧$$ $T_\ell$ is "
            r"zero unless the light reaches $P$ (${N \cdot \omega_i}$ is positive and nothing blocks the way) and, "
            r"besides, ${N' \cdot \omega_i}$ is positive; then $$⟦term⟧$$ with $\rho$ the albedo, $I_a$ the "
            r"ambient light (not tinted by $\rho$), $k_a$, $k_d$, $k_s$ the weights, $\nu$ the shininess and "
            r"$⟦mu_+⟧$ the highlight's cosine clamped. That cosine is Blinn's ${N' \cdot \omega_h}$ (the default), "
            r"with the half vector $$⟦omega_h⟧$$ or Phong's ${\omega_r \cdot \omega_o}$, with $⟦omega_r⟧$ ($\omega_i$ "
            r"mirrored in $N'$), which the kernel evaluates as $⟦phong⟧$. A sphere's albedo is its own. The floor, "
            r"at $⟦on_floor⟧$, carries no bump: its $N$ and $N'$ are both $⟦up⟧$. Its albedo is a checker of unit "
            r"squares, its red and green dimmed by the tint $\tau$: $$⟦floor⟧$$ where the grey $c$ is $⟦light⟧$ "
            r"on the squares where $⟦square⟧$ and $⟦dark⟧$ on the others. The unbumped geometry alone decides which "
            r"lights reach $P$: ⟪no-boundary⟫. The proof checks Phong's two "
            r"forms and the half vector; the formula is checked on rendered pixels of both models, on the spheres "
            r"and the floor."),
        steps=(
            Step(r"The dot product is linear, so with ${\omega_r = 2(N' \cdot \omega_i)N' - \omega_i}$ the cosine "
                 r"needs no mirror vector formed", Dot(WR, WO), phong),
            Step(r"With ${N' \cdot N'} = {\omega_i \cdot \omega_i} = 1$: ${N' \cdot \omega_r} = "
                 r"{2 N' \cdot \omega_i} - {N' \cdot \omega_i}$ and ${\omega_r \cdot \omega_r} = "
                 r"{4(N' \cdot \omega_i)^2} - {4(N' \cdot \omega_i)^2} + 1$: the same angle to $N'$ as $\omega_i$, "
                 r"and unit", *reflects),
            Step(r"For unit $\omega_i$, $\omega_o$ (not opposite), ${\omega_h \cdot \omega_i} - "
                 r"{\omega_h \cdot \omega_o}$ is ${\omega_i \cdot \omega_i} - {\omega_o \cdot \omega_o} = 0$ "
                 r"over $\lVert\omega_i + \omega_o\rVert$: equal angles to both; and $\omega_h$ is divided by its "
                 r"length", *bisects),
        ),
        claims={"phong": (Dot(WR, WO), phong)},
        shown={"colour": sp.Eq(I, COLOUR, evaluate=False), "term": sp.Eq(T[ell], TERM, evaluate=False),
               "floor": sp.Eq(rho, FLOOR, evaluate=False), "up": sp.Tuple(0, 0, 1),
               "on_floor": sp.Eq(sp.Symbol("P"), sp.Tuple(X, Y, 0), evaluate=False),
               **dict(zip(("light", "dark"), (sp.Float(g, 15) for g in greys()))), "square": checker().args[0].cond},
        where={WR: mirror, HV: half, **LENGTH, **CLAMP, **UNIT}, names=NAMES, domain=DOMAIN, evidence=partial(_evidence, **evidence),
        wrong_variants=(
            ("Phong's cosine without its - omega_i . omega_o",
             lambda: _theorem(phong=2 * Dot(NP, WI) * Dot(NP, WO)).check()),
            ("the mirror direction 2 (N' . omega_i) N' + omega_i", lambda: _theorem(mirror=2 * Dot(NP, WI) * NP + WI).check()),
            ("the half vector omega_i + omega_o, not divided by its length", lambda: _theorem(half=WI + WO).check()),
            ("the unbumped normal N in place of N'", lambda: _theorem(normal="N").check()),
            ("the highlight kept where N' . omega_i is not positive", lambda: _theorem(gate=False).check()),
            ("sphere B casting no shadow", lambda: _theorem(shadows=False).check()),
            ("the ambient light times the albedo, k_a rho I_a, as many textbooks write it",
             lambda: _theorem(colour_of=COLOUR.xreplace({I_a: rho * I_a})).check()),
            ("the albedo on the highlight too",
             lambda: _theorem(term=I_l * rho * (k_d * Dot(NP, WI) + k_s * S_PLUS ** nu)).check()),
            ("the floor's tint taken from its blue as well", lambda: _theorem(floor=sp.Tuple(*[FLOOR[0]] * 3)).check()),
            ("the tint tau kept, not taken away, (tau c, tau c, c)",
             lambda: _theorem(floor=FLOOR.xreplace({1 - tau: tau})).check()),
            ("the checker's light and dark squares swapped", lambda: _theorem(grey=checker(*greys()[::-1])).check()),
            ("the checker dark where sin(pi x) sin(pi y) is 0",
             lambda: _theorem(grey=checker().replace(sp.GreaterThan, sp.StrictGreaterThan)).check()),
            ("sphere A unbumped too, N' = N", lambda: _theorem(unbumped=("sphere A", "sphere B", "floor")).check()),
        ),
    )


#: This module's theorem: id -> title.
TITLES = {"shading": "The shading of a pixel"}

titles, build = catalogue(TITLES, {"shading": _theorem})
