"""Errata of the seed's renderer code, each measured on the project's scene.

Every record names where the seed says it (section or cell), what the seed's
code does, the test in ``tests/`` that exposes the defect, and a ``measure()``
that recomputes the evidence from scratch at build time.  The book's errata
section words these records (book/chapter/errata_words.py) from the numbers;
none of them is typed by hand.

The seed variants below re-derive the seed's formulas in vectorized form for
measurement only; the renderer never uses them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import sympy as sp

from renderer import DRAFT_SCENE, gbuffer, pointwise
from renderer import formulas as F
from renderer.pointwise import chart, tangent_frame
from renderer.render import FLOOR, SPHERE_A, SPHERE_B, image_plane
from renderer.validate import InvalidValue, positive_int

from ._checks import MAX_SQUARE, instance, shown

__all__ = ["Erratum", "ERRATA", "measure_all", "reproduced", "ErratumVanished", "seed_chamber"]

#: Resolution of the measurements (the seed's own 256 x 256 frames).
SIZE = 256
#: The draft's strong bump of its Cell 6 (``{**SC9, 'beta': 1.5, 'hf': 'sine'}``), beside its scene's own β,
#: and the field it bumps.
CELL6_BETA, CELL6_FIELD = 1.5, "sine"


@dataclass(frozen=True)
class Erratum:
    """One defect of the seed's code, with its measured evidence (a dict of numbers); the
    book's sentences about it (its title, the correction, the finding) are in
    book/chapter/errata_words.py."""

    id: str
    where: str
    seed: str          # what the seed's code does, as the draft writes it (LaTeX allowed)
    exposed_by: str    # the test (tests/ or verify/) that fails on the seed's variant
    measure: Callable[[], dict] = field(repr=False)
    #: When the defect counts as still there, as `reproduced`'s error message states it, and
    #: as a test of the measured dict (`reproduced` applies it).
    criterion: str = ""
    present: Callable[[dict], bool] = field(default=lambda m: False, repr=False)


def _rays(scene, size=SIZE):
    x, y = image_plane(scene.radius_a, scene.camera_z, size, size)
    return np.tile(x, size), np.repeat(y, size)


def _sphere_b_seed_vs_true(size=SIZE):
    """The seed's sphere-B quadratic uses c = |C_B|^2 - r^2 instead of |E - C_B|^2 - r^2."""
    scene = DRAFT_SCENE
    X, Y = _rays(scene, size)
    e = scene.camera_z
    C = np.asarray(scene.center_b)
    r = scene.radius_b
    a = X * X + Y * Y + e * e
    b = -C[0] * X - C[1] * Y - (e - C[2]) * e
    c_seed = C @ C - r * r
    disc = b * b - a * c_seed
    hit = disc >= 0
    t = (-b[hit] - np.sqrt(disc[hit])) / a[hit]
    P = np.stack([t * X[hit], t * Y[hit], e * (1 - t)], axis=-1)
    off = np.abs(np.linalg.norm(P - C, axis=-1) - r)
    # Chamber of the seed's scene: nearest of A (which the seed intersects
    # correctly), the seed's sphere B, and the floor at t = 1.
    g = gbuffer(scene, size, size)
    tB_seed = np.full(X.shape, np.inf)
    tB_seed[hit] = t
    gA = gbuffer(scene.replace(sphere_b=False), size, size)      # A unoccluded by B
    tA_all = np.where(gA.chamber.ravel() == SPHERE_A, gA.t.ravel(), np.inf)
    seed_code = np.full(X.shape, FLOOR, dtype=np.uint8)
    seed_code[tA_all <= np.minimum(tB_seed, 1.0)] = SPHERE_A
    seed_code[(tB_seed < tA_all) & (tB_seed < 1.0)] = SPHERE_B
    true_code = g.chamber.ravel()
    _SEED_CHAMBER[size] = seed_code.reshape(size, size)
    return {
        "off_surface_max": float(off.max()),
        "off_surface_relative": float(off.max() / r),
        "seed_pixels_a": int(np.count_nonzero(seed_code == SPHERE_A)),
        "seed_pixels_b": int(np.count_nonzero(seed_code == SPHERE_B)),
        "true_pixels_b": int(np.count_nonzero(true_code == SPHERE_B)),
        "chamber_flips": int(np.count_nonzero(seed_code != true_code)),
        "pixels": size * size,
    }


#: The draft's chamber map per frame size, kept by `_sphere_b_seed_vs_true` (see `seed_chamber`).
_SEED_CHAMBER = {}


def seed_chamber(size=SIZE):
    """(size, size) uint8: the chamber map the draft's code computes for its scene, its
    sphere B intersected with the draft's quadratic (erratum sphere-b-quadratic); not
    this renderer's map of the same scene (`renderer.gbuffer`).  ``size``: an int in [1, 4096]
    (InvalidType or InvalidValue naming ``size`` otherwise)."""
    size = positive_int("size", size, high=MAX_SQUARE)
    if size not in _SEED_CHAMBER:
        _sphere_b_seed_vs_true(size)
    return _SEED_CHAMBER[size]


def _light_terms(scene, size=SIZE, gradient="exact"):
    """Per sphere-A pixel and light: geometric and perturbed cosines, cast shadow."""
    g = gbuffer(scene, size, size, gradient=gradient)
    a = g.chamber == SPHERE_A
    P, N, Ns = g.P[a], g.N[a], g.Ns[a]
    out = []
    for light in scene.lights:
        L = np.asarray(light.position)
        w = L - P
        w_hat = w / np.linalg.norm(w, axis=-1, keepdims=True)
        # Cast shadow by sphere B (the only blocker of sphere A), seed quadratic.
        C, r = np.asarray(scene.center_b), scene.radius_b
        seg, pc = w, P - C
        A2 = np.einsum("ij,ij->i", seg, seg)
        B2 = np.einsum("ij,ij->i", pc, seg)
        C2 = np.einsum("ij,ij->i", pc, pc) - r * r
        D = B2 * B2 - A2 * C2
        sq = np.sqrt(np.maximum(D, 0))
        s1, s2 = (-B2 - sq) / A2, (-B2 + sq) / A2
        cast = (D >= 0) & (((s1 > 0) & (s1 < 1)) | ((s2 > 0) & (s2 < 1)))
        out.append((light, np.einsum("ij,ij->i", N, w_hat), np.einsum("ij,ij->i", Ns, w_hat),
                    cast))
    return out


def _terminator_leak(size=SIZE):
    """The seed lets a light reach a bumped pixel whose geometric normal faces away."""
    res = {}
    leaked_by_beta = {}
    for beta in (DRAFT_SCENE.beta, CELL6_BETA):
        scene = DRAFT_SCENE.replace(beta=beta)  # at beta = 0, N' = N and nothing can leak
        count = 0
        worst = 0.0
        for light, cos_geo, cos_bump, cast in _light_terms(scene, size):
            leak = (cos_geo <= 0) & (cos_bump > 0) & ~cast
            count += int(np.count_nonzero(leak))
            if leak.any():
                diffuse = scene.kd * max(scene.albedo_a) * max(light.color) * cos_bump[leak]
                worst = max(worst, float(diffuse.max()))
        leaked_by_beta[beta] = (count, worst)
    res["leak_pixels_default"], res["leak_diffuse_max_default"] = leaked_by_beta[DRAFT_SCENE.beta]
    res["leak_pixels_beta_1_5"], res["leak_diffuse_max_beta_1_5"] = leaked_by_beta[CELL6_BETA]
    res["beta_default"], res["beta_large"] = DRAFT_SCENE.beta, CELL6_BETA
    return res


def _specular_ungated(size=SIZE):
    """The seed adds a Blinn lobe where the shading normal faces away from the light."""
    scene = DRAFT_SCENE
    g = gbuffer(scene, size, size)
    E = np.array([0.0, 0.0, scene.camera_z])
    worst, count = 0.0, 0
    for kind in (SPHERE_A, SPHERE_B):
        m = g.chamber == kind
        P, Ns = g.P[m], g.Ns[m]
        v = E - P
        v /= np.linalg.norm(v, axis=-1, keepdims=True)
        for light in scene.lights:
            w = np.asarray(light.position) - P
            w /= np.linalg.norm(w, axis=-1, keepdims=True)
            h = w + v
            h /= np.linalg.norm(h, axis=-1, keepdims=True)
            mu = np.einsum("ij,ij->i", Ns, w)
            spec = np.maximum(np.einsum("ij,ij->i", Ns, h), 0) ** scene.shininess
            bad = (mu <= 0) & (spec > 0)
            count += int(np.count_nonzero(bad))
            if bad.any():
                worst = max(worst, float((scene.ks * spec[bad] * max(light.color)).max()))
    return {"pixels": count, "max_specular_added": worst}


#: The steps below the draft's at which erratum v-border-branch is measured as well.
BORDER_STEPS = (1e-6, 1e-9)


def _v_border_branch(size=SIZE):
    """The seed's border test ``vp - vm < 2 eps`` also fires in the interior: at the draft's step and at
    `BORDER_STEPS`, listed in ``steps``.  Per step: ``fraction_interior``, the share of interior sphere-A
    pixels where it fires; ``rel_change``, the largest relative change of the divisor there (the seed
    divides by the rounded span vp - vm instead of 2 eps); ``nearer``, the share of those pixels where
    that quotient is the nearer to the exact h_v (`pointwise.exact_gradient`): the span takes the
    rounding of the arguments out."""
    scene = DRAFT_SCENE
    g = gbuffer(scene, size, size)
    u, v = (g.uv[..., i][g.chamber == SPHERE_A] for i in (0, 1))
    steps = (scene.eps, *BORDER_STEPS)
    out = {"steps": list(steps), "fraction_interior": [], "rel_change": [], "nearer": []}
    for eps in steps:
        vp, vm = np.minimum(1.0, v + eps), np.maximum(0.0, v - eps)
        interior = (v + eps <= 1.0) & (v - eps >= 0.0)
        fires = interior & (vp - vm < 2 * eps)
        span = (vp - vm)[fires]
        rel = np.abs(span / (2 * eps) - 1.0)
        dh = (pointwise.height(scene.field, u[fires], vp[fires], scene.k_u, scene.k_v)
              - pointwise.height(scene.field, u[fires], vm[fires], scene.k_u, scene.k_v))
        exact = pointwise.exact_gradient(scene.field, u[fires], v[fires], scene.k_u, scene.k_v)[1]
        nearer = np.abs(dh / span - exact) < np.abs(dh / (2 * eps) - exact)
        out["fraction_interior"].append(float(np.count_nonzero(fires) / np.count_nonzero(interior)))
        out["rel_change"].append(float(rel.max()) if rel.size else 0.0)
        out["nearer"].append(float(nearer.mean()) if nearer.size else 0.0)
    return out


def _acos_pole():
    """v = acos(N_z)/pi loses digits near the pole; atan2(sin phi, N_z) does not."""
    rng = np.random.default_rng(9)
    # Normals at sin(phi) = 1e-8 ... 1e-2 around the north pole, rounded to float64.
    sin_phi = 10.0 ** rng.uniform(-8, -2, 2000)
    theta = rng.uniform(-np.pi, np.pi, 2000)
    phi = np.arcsin(sin_phi)
    N = np.stack([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)])
    N /= np.linalg.norm(N, axis=0)
    v_acos = np.arccos(np.clip(N[2], -1, 1))
    from proofs.frame import PHI_OF_V                    # phi of the chart's v
    _, v_atan, _ = chart(*N)
    v_atan = sp.lambdify(F.v, PHI_OF_V)(v_atan)
    # Reference: phi of the float64 vector, from its exact components (mpmath, 40 digits).
    import mpmath
    with mpmath.workdps(40):
        ref = np.array([float(mpmath.atan2(mpmath.hypot(mpmath.mpf(x), mpmath.mpf(y)), mpmath.mpf(z)))
                        for x, y, z in N.T])
    rel_acos = np.abs(v_acos - ref) / ref
    rel_atan = np.abs(v_atan - ref) / ref
    return {"max_rel_error_acos": float(rel_acos.max()),
            "max_rel_error_atan2": float(rel_atan.max())}


def _fallback_orientation():
    """(e_theta x e_phi) . N is -1 on the chart frame but +1 on the fallback at the north pole (the
    fallback's fixed pair gives -1 at the south pole, where N is reversed)."""
    rng = np.random.default_rng(3)
    theta = rng.uniform(-np.pi, np.pi, 1000)
    phi = rng.uniform(0.05, np.pi - 0.05, 1000)
    N = np.stack([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)])
    et, ep = tangent_frame(*N, np.hypot(N[0], N[1]))
    regular = np.einsum("ij,ij->j", np.cross(np.stack(et), np.stack(ep), axis=0), N)
    poles = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, -1.0]])              # north, south
    et0, ep0 = tangent_frame(*poles, np.zeros(2))
    fallback = np.einsum("ij,ij->j", np.cross(np.stack(et0), np.stack(ep0), axis=0), poles)
    return {"orientation_regular_min": float(regular.min()),
            "orientation_regular_max": float(regular.max()),
            "orientation_fallback": float(fallback[0]), "orientation_fallback_south": float(fallback[1])}


ERRATA = (
    Erratum(
        id="sphere-b-quadratic",
        where="Cell 1 and Cell 3 (render loops)",
        seed=r"constant term $c = |C_B|^2 - r_B^2$",
        exposed_by="tests/test_geometry_invariants.py (hit points on the surface)",
        measure=_sphere_b_seed_vs_true,
        criterion="the draft's hit points lie over one radius off sphere B, which covers over 5 times the true pixels",
        present=lambda m: m["off_surface_relative"] > 1.0 and m["seed_pixels_b"] > 5 * m["true_pixels_b"],
    ),
    Erratum(
        id="terminator-leak",
        where="Cell 1, `shade1`, used by Cells 1, 3, 5 and 6",
        seed=r"a light counts wherever $N'\cdot\omega_i > 0$; the geometric normal is never asked",
        exposed_by="tests/test_parity.py (scalar reference with geometric shadow predicate)",
        measure=_terminator_leak,
        criterion="the draft's rule lights a pair beyond the terminator at the default β, by more than one 8-bit level",
        present=lambda m: m["leak_pixels_default"] > 0 and m["leak_diffuse_max_default"] > 1 / 255,
    ),
    Erratum(
        id="specular-ungated",
        where="Cell 1, `shade1`",
        seed=r"$k_s \max(0, N'\cdot\omega_h)^{\nu}$ added for every unshadowed light",
        exposed_by="verify/test_errata.py (highlight where the bumped normal faces away)",
        measure=_specular_ungated,
        criterion="some pair facing away from its light receives a nonzero highlight",
        present=lambda m: m["pixels"] > 0 and m["max_specular_added"] > 0,
    ),
    Erratum(
        id="v-border-branch",
        where="Cell 1, `grad_numeric`",
        seed=(r"the border branch, dividing by $v_+ - v_-$ instead of $2\varepsilon$, whenever "
              r"$\mathrm{fl}(v_+ - v_-) < 2\varepsilon$, which rounding makes true away from the border"),
        exposed_by="verify/test_theorems.py (central-difference-truncation: interior points take the 2 eps branch)",
        measure=_v_border_branch,
        criterion=f"the branch fires at some interior pixels at a step of {DRAFT_SCENE.eps:g}, and at more at "
                  f"{BORDER_STEPS[-1]:g}",
        present=lambda m: 0 < m["fraction_interior"][0] < m["fraction_interior"][-1],
    ),
    Erratum(
        id="acos-pole",
        where="Cell 1, `chartA1`",
        seed=r"$\varphi = \arccos N_z$ and $\sin\varphi = \sqrt{1 - N_z^2}$",
        exposed_by="verify/test_errata.py (mpmath reference)",
        measure=_acos_pole,
        criterion="arccos loses more than 1e-3 (relative) while atan2 stays within 1e-14",
        present=lambda m: m["max_rel_error_acos"] > 1e-3 and m["max_rel_error_atan2"] < 1e-14,
    ),
    Erratum(
        id="fallback-orientation",
        where="Cell 1, `tangent_frame`, and the draft's §7, item 4",
        seed=r"fallback $e_\theta = (1,0,0)$, $e_\varphi = (0,1,0)$",
        exposed_by="verify/test_errata.py",
        measure=_fallback_orientation,
        criterion="the fallback's orientation is +1, the regular frame's -1 to 1e-12",
        present=lambda m: (m["orientation_fallback"] == 1.0
                         and max(abs(m["orientation_regular_min"] + 1), abs(m["orientation_regular_max"] + 1)) <= 1e-12),
    ),
)


def measure_all():
    """Return {erratum id: measured dict} for every record in `ERRATA`."""
    return {e.id: e.measure() for e in ERRATA}


class ErratumVanished(AssertionError):
    """An erratum's measurement no longer shows its defect: the book's errata would be false."""


def reproduced(measured=None):
    """`measure_all`'s dict (or ``measured``), after checking that every
    erratum's defect is still there by its `Erratum.criterion`; the book's
    errata section is built from this, so its build fails on a vanished one.

    ``measured``: None, or a dict {erratum id: dict of its measured numbers} holding every
    id of `ERRATA`.

    Raises
    ------
    renderer.validate.InvalidType
        ``measured`` is not a dict, or an erratum's entry is not one (``measured[id]``).
    renderer.validate.InvalidValue
        ``measured`` lacks an erratum of `ERRATA` (naming the ids missing).
    ErratumVanished
        Naming every erratum whose measurement fails its criterion.
    """
    if measured is not None:
        instance("measured", measured, dict, "a dict {erratum id: measured dict} (measure_all's) or None")
        missing = [e.id for e in ERRATA if e.id not in measured]
        if missing:
            raise InvalidValue(f"measured must hold every erratum of ERRATA, got {shown(measured)}; missing "
                               f"{', '.join(missing)}")
        for e in ERRATA:
            instance(f"measured[{e.id!r}]", measured[e.id], dict, "a dict of measured numbers")
    measured = measure_all() if measured is None else measured
    gone = [f"{e.id}: not ({e.criterion}); measured {measured[e.id]}" for e in ERRATA
            if not e.present(measured[e.id])]
    if gone:
        raise ErratumVanished("; ".join(gone))
    return measured
